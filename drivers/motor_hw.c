/*
 * Motor PWM: Timer1 fast PWM (mode 14, TOP = ICR1) at F_CPU / 368 =
 * 20.035 kHz: above hearing (the original's 3.6 kHz whined) and well inside
 * what common H-bridges (L298, TB6612, DRV88xx) switch cleanly.
 */
#include "drivers/motor_hw.h"

#include <avr/interrupt.h>
#include <avr/io.h>

#include "firmware/board_pins.h"
#include "firmware/clock.h"
#include "firmware/pins.h"

#define MOTOR_TOP 367  /* 368 timer cycles per PWM period */

void motor_hw_init(void)
{
	/* Zeroed at start-up, not const: a const array is .data, which links
	 * avr-libc's copy loop for its 2 bytes (24 bytes of flash). */
	static uint8_t zero[MOTOR_COUNT];
	ICR1 = MOTOR_TOP;
	TCCR1A = _BV(WGM11);
	TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS10);
	motor_hw_apply(zero, zero, 0x03);
}

/* High for OCR+1 of 368 cycles: OCR = round(pwm * 368 / 255) - 1, with
 * 368 = 255 + 113 taken apart: pwm * 255 divides exactly, and
 * (pwm * 113 + 127) / 255 is (y + y / 256) / 256 with y = pwm * 113 + 128,
 * the same for every pwm from 1 to 255 (all 255 compared when it was
 * written; tests/sim/test_drv_motor.py measures the duty on the pins): a
 * multiply and a few adds, where libgcc's division took ~190 cycles a
 * motor (~380 a step of the control loop). */
_Static_assert(MOTOR_TOP == 367, "the division's stand-in is for 368 = 255 + 113");
static uint16_t motor_ocr(uint8_t pwm)
{
	uint16_t y = (uint16_t)(pwm * 113u + 128u);

	return (uint16_t)(pwm + ((uint16_t)(y + (y >> 8)) >> 8) - 1);
}

void motor_hw_apply(const uint8_t *pwm, const uint8_t *dir, uint8_t lines)
{
	uint16_t ocr[MOTOR_COUNT];
	uint8_t com_on = 0;
	uint8_t com_off = 0;
	for (uint8_t m = 0; m < MOTOR_COUNT; m++) {
		uint8_t com = m ? _BV(COM1B1) : _BV(COM1A1);
		ocr[m] = pwm[m] ? motor_ocr(pwm[m]) : 0;
		if (lines & (1u << m)) {
			if (pwm[m] != 0 && pwm[m] != 255) {
				com_on |= com;
			} else {
				com_off |= com;
			}
		}
	}
	/* OCR1A/B are double-buffered up to the next PWM period: written
	 * together, both motors change in the same period, with interrupts
	 * off, not across the end of a period (or the motors would change a
	 * period apart: the wait for it is with interrupts on), after the
	 * servo's compare if it waits (clock_lock()). */
	uint8_t sreg;
	for (;;) {
		sreg = clock_lock();
		if (TCNT1 <= MOTOR_TOP - 32) {
			break;
		}
		SREG = sreg;
	}
	OCR1A = ocr[0];
	OCR1B = ocr[1];
	TCCR1A = (uint8_t)((TCCR1A & ~com_off) | com_on);
	SREG = sreg;
	for (uint8_t m = 0; m < MOTOR_COUNT; m++) {
		uint8_t d = MOTOR_PIN(BF_MOTOR_DIR, m);
		pins_drive(d, dir[m]);
		if (lines & (1u << m)) {
			/* 0 and 255 are steady levels from the port with the compare
			 * output disconnected: at OCR 0 the output would still spike
			 * once a period, and OCR = TOP relies on compare and overflow
			 * meeting in the same cycle. */
			uint8_t p = MOTOR_PIN(BF_MOTOR_PWM, m);
			pins_drive(p, pwm[m] == 255);
		}
	}
}
