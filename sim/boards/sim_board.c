/*
 * sim_board.c: building one board: firmware, MCU and the models around it.
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "sim_elf.h"
#include "sim_regbit.h"

#include "boards/sim_board.h"
#include "periph/io_hook.h"
#include "simavr16/watchdog.h"

/* simavr chatters on stdout (the ELF loader's "Loaded ..."); the contract
 * allows one line there. Errors go to stderr, the rest nowhere. */
static void sim_board_logger(avr_t *avr, const int level, const char *fmt, va_list ap)
{
	(void)avr;
	if (level <= LOG_ERROR) {
		vfprintf(stderr, fmt, ap);
	}
}

/* The firmware never sleeps; should it, simavr would usleep() to wall time.
 * Simulated time must not depend on wall time, so sleeping costs nothing. */
static void sim_board_sleep(avr_t *avr, avr_cycle_count_t how_long)
{
	(void)avr;
	(void)how_long;
}

static void sim_board_reset_hook(avr_io_t *io)
{
	sim_board_t *b = (sim_board_t *)((char *)io - offsetof(sim_board_t, reset_watch));
	/* A reset the control socket asked for names its cause; any other is
	 * the watchdog's (its reset hook, first in the list, set WDRF). */
	const char *cause = b->bm.reset_cause;

	if (!cause) {
		cause = (b->wd.wd && avr_regbit_get(io->avr, b->wd.wd->wdrf)) ? "watchdog" : "other";
	}
	if (b->addr) {
		trace_event(b->trace, io->avr->cycle, "reset %02X %s", b->addr, cause);
	} else {
		trace_event(b->trace, io->avr->cycle, "reset %s", cause);
	}
}

/* The PC's waveform on the gateway's RXD pin. */
static void sim_board_rxd(void *param, int level, avr_cycle_count_t cycle)
{
	sim_board_t *b = param;

	(void)cycle;	/* an edge from outside: PINx sees it now */
	board_model_drive(&b->bm, b->rxd_port, b->rxd_bit, level);
}

/* The board's frames on its TXD pin, each edge at its cycle. */
static void sim_board_txd(void *param, int level, avr_cycle_count_t cycle)
{
	sim_board_t *b = param;

	board_model_uart_drive(&b->bm, b->txd_port, b->txd_bit, level, cycle);
}

int sim_board_init(sim_board_t *b, const sim_board_desc_t *board, const char *elf,
		   uint8_t addr, twi_bus_t *bus, trace_t *trace,
		   usart_to_host_t to_host, void *to_host_param)
{
	elf_firmware_t fw;
	/* A slave's serial port and SPI go nowhere; keeping them out of the
	 * trace keeps the gateway's `uart`/`spi` lines unambiguous. */
	trace_t *local_trace = addr ? NULL : trace;

	b->board = board;
	b->addr = addr;
	b->trace = trace;
	if (addr) {
		snprintf(b->prefix, sizeof(b->prefix), "%02X", addr);
	} else {
		b->prefix[0] = 0;
	}
	avr_global_logger_set(sim_board_logger);
	memset(&fw, 0, sizeof(fw));
	if (elf_read_firmware(elf, &fw) != 0 || !fw.flash || !fw.flashsize) {
		fprintf(stderr, "orfa-sim: cannot load firmware '%s'\n", elf);
		return 2;
	}
	b->mcu = sim_mcu_find(board->mcu);
	b->avr = avr_make_mcu_by_name(board->mcu);
	if (!b->mcu || !b->avr) {
		fprintf(stderr, "orfa-sim: simavr lacks MCU '%s'\n", board->mcu);
		return 2;
	}
	avr_init(b->avr);
	if (fw.flashsize > b->avr->flashend + 1u) {
		fprintf(stderr, "orfa-sim: '%s' does not fit the %s's flash\n", elf, board->mcu);
		return 2;
	}
	avr_load_firmware(b->avr, &fw);
	b->avr->frequency = board->hz;	/* our ELFs carry no .mmcu */
	b->avr->sleep = sim_board_sleep;

	usart_init(&b->usart, b->avr, &b->mcu->usart[board->wiring.host_usart],
		   local_trace, to_host, to_host_param);
	sim_twi_init(&b->twi, b->avr, &b->mcu->twi, bus);
	if (board_model_init(&b->bm, b->avr, board, b->mcu, local_trace) < 0) {
		fprintf(stderr, "orfa-sim: cannot build the %s board model\n", board->name);
		return 2;
	}
	/* SCL/SDA as pins: the firmware's port drivers and the line levels */
	{
		const sim_pin_t *scl = sim_wiring_pin(&board->wiring, BF_TWI_SCL, 0);
		const sim_pin_t *sda = sim_wiring_pin(&board->wiring, BF_TWI_SDA, 0);

		if (!scl || !sda || sim_twi_wire_pins(&b->twi, scl->port, scl->bit, sda->bit) < 0 ||
		    board_model_wire_twi(&b->bm, bus) < 0) {
			fprintf(stderr, "orfa-sim: cannot wire the %s's TWI pins\n", board->name);
			return 2;
		}
	}
	if (!addr) {
		const sim_pin_t *rxd = sim_wiring_pin(&board->wiring, BF_UART_RX, 0);

		b->rxd_port = rxd ? board_model_port(&b->bm, rxd->port) : NULL;
		if (b->rxd_port) {
			b->rxd_bit = rxd->bit;
			usart_set_pin(&b->usart, sim_board_rxd, b);
		}
	}
	{
		const sim_pin_t *txd = sim_wiring_pin(&board->wiring, BF_UART_TX, 0);

		b->txd_port = txd ? board_model_port(&b->bm, txd->port) : NULL;
		if (b->txd_port) {
			b->txd_bit = txd->bit;
			usart_set_tx_pin(&b->usart, sim_board_txd, b);
		}
	}
	b->reset_watch.kind = "orfa-reset";
	b->reset_watch.reset = sim_board_reset_hook;
	io_hook_register_last(b->avr, &b->reset_watch);
	simavr16_watchdog_init(&b->wd, b->avr);
	return 0;
}

uint32_t sim_board_activity(const sim_board_t *b)
{
	return b->usart.activity + b->bm.spi.activity + b->bm.activity;
}
