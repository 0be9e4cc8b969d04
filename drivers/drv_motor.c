#include "drivers/drv_motor.h"

#include <string.h>

#include "drivers/motor_hw.h"
#include "firmware/board_pins.h"
#include "firmware/pins.h"

#define MOTOR_REG_DIR1 2

/* [PWM1, PWM2, DIR1, DIR2] */
static uint8_t motor_reg[DRV_motor_NREGS];

void drv_motor_init(void)
{
	for (uint8_t i = 0; i < DRV_motor_NREGS; i++) {
		motor_reg[i] = 0;
	}
	/* Direction lines are the motors' for good; a stopped motor's PWM line
	 * (low) may be lent to servo channels 14/15. */
	for (uint8_t m = 0; m < MOTOR_COUNT; m++) {
		pins_claim(MOTOR_PIN(BF_MOTOR_DIR, m), PIN_MOTOR);
		pins_claim(MOTOR_PIN(BF_MOTOR_PWM, m), PIN_MOTOR_IDLE);
	}
	motor_hw_init();
}

/* What a write's bytes so far rule out (regmap.h): refused at once. */
reg_status_t drv_motor_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)data;
	/* too many registers; a bad direction is left to the write, which
	 * tells a too long write first */
	return reg + len > DRV_motor_NREGS ? REG_BAD_LENGTH : REG_OK;
}

/* A write of k bytes to register r sets registers r..r+k-1 (4 bytes to PWM1
 * set all four), all of them or none. */
reg_status_t drv_motor_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	if (len == 0 || reg + len > DRV_motor_NREGS) {
		return REG_BAD_LENGTH;
	}
	uint8_t next[DRV_motor_NREGS];
	/* memcpy (linked already): the compiler's copies were a load and a
	 * store per byte */
	memcpy(next, motor_reg, DRV_motor_NREGS);
	memcpy(next + reg, data, len);
	for (uint8_t m = 0; m < MOTOR_COUNT; m++) {
		if (next[MOTOR_REG_DIR1 + m] > 1) {
			return REG_BAD_VALUE;
		}
	}
	/* A running motor needs its PWM line: a servo may hold it. */
	for (uint8_t m = 0; m < MOTOR_COUNT; m++) {
		uint8_t pin = MOTOR_PIN(BF_MOTOR_PWM, m);
		if (next[m] && pins_owner(pin) != PIN_MOTOR && pins_owner(pin) != PIN_MOTOR_IDLE) {
			return REG_PIN_BUSY;
		}
	}
	uint8_t lines = 0;
	for (uint8_t m = 0; m < MOTOR_COUNT; m++) {
		if (pins_claim(MOTOR_PIN(BF_MOTOR_PWM, m), next[m] ? PIN_MOTOR : PIN_MOTOR_IDLE)) {
			lines |= (uint8_t)(1u << m);
		}
	}
	motor_hw_apply(&next[0], &next[MOTOR_REG_DIR1], lines);
	memcpy(motor_reg, next, DRV_motor_NREGS);
	return REG_OK;
}

/* Reading register r gives registers r..3. */
uint8_t drv_motor_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	uint8_t n = 0;
	for (uint8_t r = reg; r < DRV_motor_NREGS && n < max; r++) {
		dst[n++] = motor_reg[r];
	}
	return n;
}

void drv_motor_safe(void)
{
	const uint8_t stop[MOTOR_COUNT] = { 0, 0 };
	(void)drv_motor_write(0, stop, MOTOR_COUNT);  /* PWM 0 is always taken */
}
