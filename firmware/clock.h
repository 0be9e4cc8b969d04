/*
 * The board's time base: an 8-bit timer counting F_CPU/8 whose overflow
 * interrupt counts wraps, so one tick is 2048 cycles (1/3600 s at
 * 7.3728 MHz). The board file names the timer (BOARD_CLOCK_TIMER). Bus
 * timeouts and the link-loss failsafe measure time with it; it runs in
 * every build, whatever drivers are linked.
 */
#ifndef ORFA_CLOCK_H
#define ORFA_CLOCK_H

#include <stdint.h>

#define CLOCK_TICK_CYCLES 2048UL
#define CLOCK_HZ (F_CPU / CLOCK_TICK_CYCLES)
/* Ticks in `ms` milliseconds, rounded up (a constant expression). */
#define CLOCK_TICKS_MS(ms) ((uint16_t)(((ms) * CLOCK_HZ + 999UL) / 1000UL))

/* Timer overflows so far; the timer's count is the low byte of a tick.
 * Written by the overflow interrupt, and by code that runs with interrupts
 * off and counts an overflow whose interrupt is pending (servo_pins.c). */
extern volatile uint16_t clock_wraps;

void clock_init(void);

/* The time base's compare interrupt (a driver's: the M32-D's servo edges)
 * turned on by the overflow interrupt when the wraps reach `wrap` (their
 * low byte; at the first wrap at or after it, within 127), its flag
 * cleared first (matches while it was off): a driver whose next compare
 * is wraps away turns the interrupt off meanwhile rather than wake at
 * every wrap, and names a wrap before its compare's own. Interrupts off.
 * Boards whose file defines BOARD_CLOCK_COMPARE. */
void clock_compare_from(uint8_t wrap);
void clock_compare_cancel(void);

/* Interrupts off for a short section, once the compare interrupt is not
 * waiting (it runs first, then they go off again): the AVR runs one
 * instruction after an interrupt's RETI, and if that is the section's CLI
 * the compare would wait for the section as well as the interrupt, more
 * than its lead allows for. Returns SREG as it was, for the caller to put
 * back. Called with interrupts on (or with the compare off). */
uint8_t clock_lock(void);

/* Ticks since clock_init, wrapping every 65536 (18.2 s): differences of
 * two readings are exact up to that. Interrupts stay on. */
uint16_t clock_now(void);

/* The low byte of clock_now(), one load (AVR: little-endian): enough for a
 * bound below 256 ticks, and cheap in an interrupt. */
static inline uint8_t clock_now8(void)
{
	return *(volatile const uint8_t *)&clock_wraps;
}

#endif
