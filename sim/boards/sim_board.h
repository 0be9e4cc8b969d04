/*
 * sim_board.h: one simulated board of the world (world.h): its MCU running
 * a firmware, and the models the simulator puts around that MCU (USART,
 * TWI, board model with its signals), plus the watch that traces a reset.
 *
 * The gateway board's serial port reaches the PC; a slave board's USART is
 * modelled but goes nowhere. Every board's TWI hangs on the world's bus.
 */
#ifndef SIM_SIM_BOARD_H
#define SIM_SIM_BOARD_H

#include <stdint.h>

#include "sim_avr.h"

#include "boards/sim_boards.h"
#include "boards/board_model.h"
#include "periph/sim_mcu.h"
#include "harness/trace.h"
#include "periph/sim_twi.h"
#include "periph/twi_bus.h"
#include "periph/usart.h"
#include "simavr16/watchdog.h"

/* The world's clock in Hz: every board's BOARD_CLOCK_HZ (sim_boards.h). */
#define SIM_FREQUENCY (sim_boards_hz())

typedef struct sim_board_t {
	const sim_board_desc_t *board;
	const sim_mcu_t *mcu;
	avr_t *avr;
	avr_io_t reset_watch;		/* traces "reset <cause>" on every reset */
	simavr16_watchdog_t wd;		/* simavr's watchdog and its repairs */
	trace_t *trace;
	usart_t usart;
	sim_twi_t twi;
	board_model_t bm;
	bm_port_t *rxd_port;		/* gateway: its RXD pin, driven by the PC */
	int rxd_bit;
	bm_port_t *txd_port;		/* its TXD pin, driven by its USART */
	int txd_bit;
	uint8_t addr;			/* slave: 8-bit bus address (--slave); 0: gateway */
	char prefix[4];			/* "": gateway; "10": a slave's signal prefix */
} sim_board_t;

/* Load ELF into a fresh MCU of BOARD and wire up the board's parts, its TWI
 * on BUS. ADDR: 0 for the gateway, else the slave's 8-bit address. Events
 * go to TRACE (NULL: none); bytes the serial port sends go to TO_HOST.
 * Returns 0, or 2 after printing why on stderr. */
int sim_board_init(sim_board_t *b, const sim_board_desc_t *board, const char *elf,
		   uint8_t addr, twi_bus_t *bus, trace_t *trace,
		   usart_to_host_t to_host, void *to_host_param);

/* Bumps on every change a control client or the idle throttle cares for. */
uint32_t sim_board_activity(const sim_board_t *b);

#endif
