/*
 * board_model.h: the parts of a board outside the MCU, wired from
 * boards/<board>/board.h (board_wiring.h):
 *
 *  - every port pin as a signal ("A0".."G7") with cycle-exact edges. Level:
 *    output -> PORT, or the compare output while the timer's COM bits are on
 *    (from TIMER_IRQ_OUT_COMP, stamped at the compare's own cycle), or the
 *    SPI master's SCK/MOSI while SPE and MSTR; input -> the external drive,
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

#include "board.h"
#include "board_wiring.h"
#include "mcu.h"
#include "signals.h"
#include "spi.h"
#include "trace.h"
#include "twi_bus.h"
#include "parts/cd4017.h"
#include "parts/eeprom25.h"
#include "parts/mcp3008.h"

#define BM_MAX_PORTS 7
#define BM_MAX_OC 12
#define BM_MAX_SPI_DEV 8

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
	uint8_t spi_mask, spi_level;	/* driven by the SPI master */
	uint8_t wired;			/* the I2C bus's lines (board_model_wire_twi) */
	signal_t pin[8];
	bm_oc_t *oc[8][2];
	int noc[8];
	avr_io_read_t pin_read;		/* simavr's PINx read, chained */
	void *pin_read_param;
} bm_port_t;

/* simavr's write handler of a register the board model took over. */
typedef struct bm_chain_t {
	avr_io_write_t w;	/* NULL: a plain store */
	void *param;
} bm_chain_t;

typedef struct bm_com_hook_t {
	struct board_model_t *bm;
	uint16_t addr;
	bm_chain_t prev;
} bm_com_hook_t;

/* An OCRnx low-byte write handler chained by the board model (fast PWM). */
typedef struct bm_ocr_hook_t {
	struct board_model_t *bm;
	avr_timer_t *timer;
	uint16_t addr;
	bm_chain_t prev;
} bm_ocr_hook_t;

/* A PWM timer whose overflow the board model watches (OCR double buffer). */
typedef struct bm_pwm_timer_t {
	struct board_model_t *bm;
	avr_timer_t *timer;
} bm_pwm_timer_t;

/* A register with force-output-compare strobes (TCCR1C, TCCR3C). */
typedef struct bm_foc_hook_t {
	struct board_model_t *bm;
	uint16_t addr;
	bm_chain_t prev;
	struct bm_oc_t *oc[3];	/* the unit each strobe bit acts on */
	uint8_t bit[3];
	int n;
} bm_foc_hook_t;

/* A timer interrupt flag register (TIFR, ETIFR): which vectors' flags it holds. */
#define BM_MAX_FLAGS 16
typedef struct bm_flag_reg_t {
	uint16_t addr;
	avr_int_vector_t *vec[BM_MAX_FLAGS];
	int n;
} bm_flag_reg_t;

typedef struct board_model_t {
	avr_io_t io;			/* first: reset hook */
	avr_t *avr;
	/* A reset the control socket asks for (fault.h): its cause while
	 * avr_reset runs ("external", "power", "brownout"), else NULL (the
	 * watchdog's). A power-on paints SRAM again; other resets keep it,
	 * as silicon does, so .noinit data live on. */
	const char *reset_cause;
	const board_desc_t *board;
	const board_wiring_t *wiring;
	trace_t *trace;
	signals_t signals;

	bm_port_t ports[BM_MAX_PORTS];
	int nports;
	bm_oc_t oc[BM_MAX_OC];
	int noc;
	uint64_t oc_seq;
	bm_com_hook_t com[8];
	int ncom;
	bm_ocr_hook_t ocr[BM_MAX_OC];
	int nocr;
	bm_flag_reg_t flag_regs[2];
	int nflag_regs;
	bm_foc_hook_t foc[MCU_MAX_FOC];
	int nfoc;
	bm_pwm_timer_t pwm[4];
	int npwm;

	uint32_t adc_mv[8];
	uint32_t avcc, aref;
	avr_irq_t *adc_irq;

	cd4017_t cnt[4];
	int ncnt;
	signal_t servo[32];
	int nservo;

	spi_t spi;
	bm_port_t *spi_port[2];		/* SCK, MOSI */
	int spi_bit[2];
	eeprom25_t ee[BM_MAX_SPI_DEV];
	mcp3008_t mcp[BM_MAX_SPI_DEV];
	int nee, nmcp;
	uint32_t activity;		/* control-visible changes */

	twi_bus_t *twi_bus;		/* the TWI pins show its lines */
	bm_port_t *twi_port;
	int twi_scl, twi_sda;
} board_model_t;

/* Build the model around AVR (after avr_init, before the run). 0 or -1. */
int board_model_init(board_model_t *bm, avr_t *avr, const board_desc_t *board,
		     const mcu_desc_t *mcu, trace_t *trace);

/* Add an SPI device from "KIND@PIN[:mode=N][:lsb]". NULL, or an error text. */
const char *board_model_add_spi(board_model_t *bm, const char *spec);

/* The port called LETTER, or NULL. */
bm_port_t *board_model_port(board_model_t *bm, char letter);

/* Parse "A5" into port and bit. 0 or -1. */
int board_model_parse_pin(board_model_t *bm, const char *s, bm_port_t **port, int *bit);

/* Drive a pin from outside: 0, 1, or -1 to release it. */
void board_model_drive(board_model_t *bm, bm_port_t *p, int bit, int level);

/* Analog values in mV. CH 0..7. */
void board_model_set_adc(board_model_t *bm, int ch, uint32_t mv);
void board_model_set_avcc(board_model_t *bm, uint32_t mv);
void board_model_set_aref(board_model_t *bm, uint32_t mv);

/* Byte the simulator paints free SRAM with before the firmware runs. */
#define BM_PAINT 0xA5

/* Peak stack use since the last reset, in bytes: from the first byte above
 * FROM (the end of the firmware's static data, __heap_start; 0 = guess) that
 * the stack has written. *deepest = that address. -1 if FROM is not SRAM. */
int board_model_stack_peak(board_model_t *bm, uint32_t from, uint32_t *deepest);

/* The board's TWI pins (its wiring's TWI_SCL/TWI_SDA) show BUS's wired-AND
 * lines: their signals follow the line levels and PINx reads them, whoever
 * pulls (this board's pins or TWI, another board, a stuck device). */
int board_model_wire_twi(board_model_t *bm, twi_bus_t *bus);

/* "1 out", "0 in", "1 in pullup", "0 in ext", ... */
void board_model_pin_text(board_model_t *bm, bm_port_t *p, int bit, char *buf, int size);

/* The SPI device on chip-select pin NAME, or NULL. */
spi_dev_t *board_model_spi_dev(board_model_t *bm, const char *pin);

#endif
