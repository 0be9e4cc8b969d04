/*
 * Servo pulse hardware, one implementation per board family (picked by the
 * board file's BOARD_SERVO_HW): servo_pins.c drives one MCU pin per channel
 * (M32-D; servo_plan.c plans its edges), servo_4017.c clocks CD4017 decade counters (M128-S).
 */
#ifndef SERVO_HW_H
#define SERVO_HW_H

#include <stdbool.h>
#include <stdint.h>

/* Timers and pins set up; no channel pulses. */
void servo_hw_init(void);

/* Whether servo_hw_claim(ch) would succeed; changes nothing. */
bool servo_hw_can_claim(uint8_t ch);

/* Takes the pins channel `ch` needs; false if another function holds one. */
bool servo_hw_claim(uint8_t ch);

/* Gives channel `ch`'s pins back (it no longer pulses). */
void servo_hw_release(uint8_t ch);

/* Channel widths in microseconds (0 = off, else 500..2500), applied together
 * from the next 20 ms frame on; `was_us`: the widths the last call applied
 * (all 0 after servo_hw_init()), so only the channels that change need
 * planning. */
void servo_hw_apply(const uint16_t *widths_us, const uint16_t *was_us);

#endif
