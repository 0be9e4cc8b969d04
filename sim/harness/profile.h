/*
 * profile.h: where a board's cycles go (the `profile` control request):
 * the simulated cycles spent at each flash word while profiling is on,
 * counted from the run loop before each instruction (avr_step.c; no board
 * is parked, nor watched for parking, while one is profiled: park.c).
 * Every cycle between two instructions counts to the first of them: its
 * own cycles, and an interrupt's entry that follows it (4 cycles), or its
 * sleep. tools/profile.py turns the counts into a table by function,
 * source line and kind of work.
 */
#ifndef SIM_PROFILE_H
#define SIM_PROFILE_H

#include <stdint.h>

#include "sim_avr.h"

/* Boards being profiled: the run loop's test before each instruction. */
extern int profile_boards;

/* Counting for AVR from now, every count zero (again, if it was on). 0, or
 * -1 when out of memory or too many boards. */
int profile_on(avr_t *avr);

/* Counting for AVR stopped, its counts kept for profile_counts(). */
void profile_off(avr_t *avr);

/* AVR's counts so far (NULL: never profiled), one per flash word, and
 * their number in *words. */
const uint64_t *profile_counts(avr_t *avr, uint32_t *words);

void profile_note_slow(avr_t *avr);

/* Before each instruction AVR runs (and each turn it sleeps). */
static inline void profile_note(avr_t *avr)
{
	if (__builtin_expect(profile_boards != 0, 0)) {
		profile_note_slow(avr);
	}
}

#endif
