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
 * from the next 20 ms frame on (the M32-D: from the frame after
 * servo_hw_later() has planned them). */
void servo_hw_apply(const uint16_t *widths_us);

/* The part of servo_hw_apply() that waits for the main loop to come round
 * (regmap_later(), with the widths the driver holds then): the M32-D plans
 * the new edges there, once the write's reply is queued, so the line is
 * busy with it meanwhile (the control loop at 230400: 82 -> 88 % of the
 * wire); the M128-S has nothing left (it plans at once). */
void servo_hw_later(const uint16_t *widths_us);

#endif
