/* DC motor outputs (M32-D): PWM on Timer1's OC1A/OC1B, direction lines. */
#ifndef MOTOR_HW_H
#define MOTOR_HW_H

#include <stdint.h>

#define MOTOR_COUNT 2

/* Timer1 fast PWM; outputs low. */
void motor_hw_init(void);

/* Sets both motors at once: pwm[m] (duty pwm/255: 0 steady low, 255 steady
 * high) and dir[m] (1 = backward). PWM line m is driven only if bit m of
 * `lines` says the motor holds it. */
void motor_hw_apply(const uint8_t *pwm, const uint8_t *dir, uint8_t lines);

#endif
