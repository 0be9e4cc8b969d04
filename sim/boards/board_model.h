/*
 * board_model.h: the parts of a board outside the MCU, wired from
 * boards/<board>/board.h (sim_wiring.h):
 *
 *  - every port pin as a signal ("A0".."G7") with cycle-exact edges. Level:
 *    output -> PORT, or the compare output while the timer's COM bits are on
 *    (from TIMER_IRQ_OUT_COMP, stamped at the compare's own cycle), or the
 *    SPI master's SCK/MOSI while SPE and MSTR; the USART's transmitter on
 *    TXD while TXEN, whatever DDR says; input -> the external drive,
 *    else the pull-up (1) or 0 when floating without pull-up (PINx follows);
 *  - external drive of pins (0, 1 or released);
 *  - analog inputs of the ADC port, AVCC and AREF in mV;
 *  - the M128-S's CD4017 servo counters ("cnt<c>q<k>", "servo<n>");
 *  - the SPI master model and its devices (--spi).
 */
#ifndef SIM_BOARD_MODEL_H
#define SIM_BOARD_MODEL_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_io.h"
#include "avr_ioport.h"
#include "avr_timer.h"

#include "boards/sim_boards.h"
#include "boards/sim_wiring.h"
#include "periph/io_hook.h"
#include "periph/sim_mcu.h"
#include "harness/signals.h"
#include "periph/spi.h"
#include "harness/trace.h"
#include "periph/twi_bus.h"
#include "parts/cd4017.h"
#include "simavr16/timers.h"
#include "parts/part.h"

#define BM_MAX_PORTS 7
#define BM_MAX_OC 12

struct board_model_t;
struct bm_port_t;

typedef struct bm_oc_t {
	struct board_model_t *bm;
	avr_timer_t *timer;
	int comp;
	struct bm_port_t *port;
	int bit;
	int latch;			/* last level the compare unit gave */
	uint64_t seq;			/* order of the last change (shared pins) */
} bm_oc_t;

typedef struct bm_port_t {
	struct board_model_t *bm;
	char name;
	avr_ioport_t *io;
	avr_irq_t *irq;			/* the port's IRQs */
	uint8_t ddr, port;		/* shadows of DDRx/PORTx */
	uint8_t ext_mask, ext_value;	/* driven from outside */
	uint8_t spi_mask, spi_level;	/* driven by the SPI bus */
	uint8_t spi_input;		/* MISO: its device drives it whatever DDR says */
	uint8_t uart_mask, uart_level;	/* driven by the USART's transmitter */
	uint8_t wired;			/* the I2C bus's lines (board_model_wire_twi) */
	signal_t pin[8];
	bm_oc_t *oc[8][2];
	int noc[8];
	io_hook_prev_t pin_read;	/* simavr's PINx read, chained */
} bm_port_t;

/* A register holding COM bits, whose writes may give a pin a new owner. */
typedef struct bm_com_hook_t {
	struct board_model_t *bm;
	uint16_t addr;
	io_hook_prev_t prev;
} bm_com_hook_t;

typedef struct board_model_t {
	avr_io_t io;			/* first: reset hook */
	avr_t *avr;
	/* A reset the control socket asks for (fault.h): its cause while
	 * avr_reset runs ("external", "power", "brownout"), else NULL (the
	 * watchdog's). A power-on paints SRAM again; other resets keep it,
	 * as silicon does, so .noinit data live on. */
	const char *reset_cause;
	const sim_board_desc_t *board;
	const sim_wiring_t *wiring;
	trace_t *trace;
	signals_t signals;

	bm_port_t ports[BM_MAX_PORTS];
	int nports;
	bm_oc_t oc[BM_MAX_OC];
	int noc;
	uint64_t oc_seq;
	bm_com_hook_t com[8];
	int ncom;
	simavr16_timers_t s16;		/* the simavr 1.6 timer repairs */

	uint32_t adc_mv[8];
	uint32_t avcc, aref;
	avr_irq_t *adc_irq;

	cd4017_t cnt[4];
	int ncnt;
	signal_t servo[32];
	int nservo;

	spi_t spi;
	bm_port_t *spi_port[SPI_PINS];	/* SCK, MOSI, MISO */
	int spi_bit[SPI_PINS];
	part_list_t spi_parts;		/* the parts on its SPI bus (--spi) */
	uint32_t activity;		/* control-visible changes */

	twi_bus_t *twi_bus;		/* the TWI pins show its lines */
	bm_port_t *twi_port;
	int twi_scl, twi_sda;
} board_model_t;

/* Build the model around AVR (after avr_init, before the run). 0 or -1. */
int board_model_init(board_model_t *bm, avr_t *avr, const sim_board_desc_t *board,
		     const sim_mcu_t *mcu, trace_t *trace);

/* Add an SPI device from "KIND@PIN[:mode=N][:lsb]". NULL, or an error text. */
const char *board_model_add_spi(board_model_t *bm, const char *spec);

/* The port called LETTER, or NULL. */
bm_port_t *board_model_port(board_model_t *bm, char letter);

/* Parse "A5" into port and bit. 0 or -1. */
int board_model_parse_pin(board_model_t *bm, const char *s, bm_port_t **port, int *bit);

/* Drive a pin from outside: 0, 1, or -1 to release it. */
void board_model_drive(board_model_t *bm, bm_port_t *p, int bit, int level);

/* The USART's transmitter drives a pin over its port (LEVEL 0 or 1 from
 * CYCLE on), or lets it go (-1). */
void board_model_uart_drive(board_model_t *bm, bm_port_t *p, int bit, int level,
			    uint64_t cycle);

/* Analog values in mV. CH 0..7. */
void board_model_set_adc(board_model_t *bm, int ch, uint32_t mv);
void board_model_set_avcc(board_model_t *bm, uint32_t mv);
void board_model_set_aref(board_model_t *bm, uint32_t mv);

/* Recompute every pin of P at CYCLE; an input's PINx bit follows. */
void board_model_port_update(bm_port_t *p, uint64_t cycle);

/* The servo signals: CD4017 counters and their outputs, or servo pins
 * (servos.c). 0 or -1. */
int board_model_wire_servos(board_model_t *bm);

/* The board's TWI pins (its wiring's TWI_SCL/TWI_SDA) show BUS's wired-AND
 * lines: their signals follow the line levels and PINx reads them, whoever
 * pulls (this board's pins or TWI, another board, a stuck device). */
int board_model_wire_twi(board_model_t *bm, twi_bus_t *bus);

/* "1 out", "0 in", "1 in pullup", "0 in ext", ... */
void board_model_pin_text(board_model_t *bm, bm_port_t *p, int bit, char *buf, int size);

/* The SPI device on chip-select pin NAME, or NULL. */
spi_dev_t *board_model_spi_dev(board_model_t *bm, const char *pin);

#endif
