/* DC motor outputs (M32-D): PWM on Timer1's OC1A/OC1B, direction lines. */
#ifndef MOTOR_HW_H
#define MOTOR_HW_H

#include <stdint.h>

#include "firmware/board_pins.h"

#define MOTOR_COUNT 2

/* Motor m's pin of function `fn` (BF_MOTOR_PWM, BF_MOTOR_DIR): one of two
 * constants, not a search of the pin map. */
#define MOTOR_PIN(fn, m) ((m) ? board_pin_at(fn, 1) : board_pin_at(fn, 0))

/* Timer1 fast PWM; outputs low. */
void motor_hw_init(void);

/* Sets both motors at once: pwm[m] (duty pwm/255: 0 steady low, 255 steady
 * high) and dir[m] (1 = backward). PWM line m is driven only if bit m of
 * `lines` says the motor holds it. */
void motor_hw_apply(const uint8_t *pwm, const uint8_t *dir, uint8_t lines);

#endif
