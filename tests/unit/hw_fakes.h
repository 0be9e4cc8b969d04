/*
 * Host fakes of the hardware under the drivers (port_io.h, servo_hw.h,
 * motor_hw.h, adc_hw.h, spi_hw.h) for the driver unit tests
 * (build/unit/drivers-<board>). Sized by the board's board.h, so ASan
 * catches a driver reaching for a port the board does not have.
 */
#ifndef UNIT_HW_FAKES_H
#define UNIT_HW_FAKES_H

#include <stdint.h>

#include "board.h"

/* Port registers by port index (0 = A). PINx reads PORTx on outputs and
 * port_ext (the level something outside drives) on inputs. */
extern uint8_t port_out[BOARD_NPORTS];
extern uint8_t port_ddr[BOARD_NPORTS];
extern uint8_t port_ext[BOARD_NPORTS];

/* Every port_io change and SPI exchange, in order, as text:
 *   "WA08:00 "  port_io_write(A, mask 08, value 00)
 *   "DA08:08 "  port_io_dir(A, mask 08, value 08)
 *   "X9F00>C2FF "  spi_hw_exchange sent 9F 00 and received C2 FF */
extern char hw_log[8192];
void hw_log_clear(void);

/* Hardware records, compared whole by the tests ("nothing changed"). */
typedef struct {
	/* servo_hw */
	unsigned servo_inits;
	unsigned servo_applies;
	uint16_t servo_width[BOARD_SERVO_CHANNELS];  /* last servo_hw_apply */
	uint8_t servo_claimed[BOARD_SERVO_CHANNELS]; /* claimed, not released */
	unsigned servo_claims;                       /* successful claims */
	unsigned servo_releases;
	/* motor_hw */
	unsigned motor_inits;
	unsigned motor_applies;
	uint8_t motor_pwm[2];
	uint8_t motor_dir[2];
	uint8_t motor_lines;
	/* adc_hw */
	unsigned adc_configs;
	uint8_t adc_refs;
	uint8_t adc_mask;
	/* spi_hw */
	unsigned spi_inits;
	unsigned spi_configs;
	uint8_t spi_div;
	uint8_t spi_mode;
	uint8_t spi_lsb;      /* lsb_first != 0 */
	unsigned spi_bytes;   /* bytes exchanged in all */
} hw_rec_t;
extern hw_rec_t hw;

/* ADC inputs: the 10-bit value each channel converts to. Like adc_hw.c, a
 * channel gives it once the last adc_hw_config enabled it, else 0. */
extern uint16_t adc_in[8];

/* SPI: the bytes the device answers with, one per byte sent; 0xFF when
 * the script runs out. */
void spi_script(const uint8_t *miso, unsigned n);

/* Everything back to power-on: ports zero, records zero, log empty. */
void hw_fakes_reset(void);

#endif
