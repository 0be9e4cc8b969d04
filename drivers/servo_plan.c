/*
 * The M32-D servo schedule (servo_plan.h), planned in the main loop.
 */
#include "drivers/servo_plan.h"

#include <stdbool.h>

#include "firmware/flash.h"

_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES + 18432UL + 1000UL
	       < SERVO_FRAME, "the last channel's longest pulse ends inside the frame");

/* No two edges of a frame are 131072 cycles apart (SERVO_LONG covers 17
 * bits): the latest start is the last channel's, moved late. */
_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES < 0x20000UL,
	       "a delta fits 16 bits and SERVO_LONG");
_Static_assert(SERVO_CHANNELS <= SERVO_CHAN + 1, "a channel fits the edge code");

static struct {
	int8_t move[SERVO_CHANNELS];     /* each channel's place: SERVO_SHIFTs off its slot */
	uint16_t width[SERVO_CHANNELS];  /* cycles, as last planned; 0 = off */
} pl;

/* Frame offset of each channel's pulse start. */
static const ORFA_FLASH uint32_t slot_start[SERVO_CHANNELS] = {
#define S(n) SERVO_SLOT * (n)
	S(0), S(1), S(2), S(3), S(4), S(5), S(6), S(7),
	S(8), S(9), S(10), S(11), S(12), S(13), S(14), S(15),
#undef S
};
_Static_assert(SERVO_CHANNELS == 16, "slot_start lists 16 channels");

/* Cycles for a width in microseconds, rounded to the nearest: us * 7.3728
 * as a 16.16 fixed-point product (a division took 600 cycles a channel). */
#define SERVO_CYCLES_PER_US_Q16 ((uint32_t)((F_CPU * 65536ULL + 500000ULL) / 1000000ULL))
static uint16_t servo_cycles(uint16_t us)
{
	return (uint16_t)(((uint32_t)us * SERVO_CYCLES_PER_US_Q16 + 32768UL) >> 16);
}

/* Edge times in the planning are kept in 8-cycle units, 16 bits: a frame is
 * 18432 of them, and edges SERVO_GAP apart stay apart. */
#define SERVO_GAP8 (SERVO_GAP / 8)

/* Whether an edge at `t8` keeps SERVO_GAP from the edges in `at8`, except
 * those of channel `self`. */
static bool servo_clear_of(uint16_t t8, const uint16_t *at8, const uint8_t *edge, uint8_t n,
			   uint8_t self)
{
	for (uint8_t i = 0; i < n; i++) {
		int16_t d = (int16_t)(t8 - at8[i]);
		if ((edge[i] & SERVO_CHAN) != self && d < SERVO_GAP8 && d > -SERVO_GAP8) {
			return false;
		}
	}
	return true;
}

void servo_plan(servo_sched_t *s, const uint16_t *widths_us)
{
	uint16_t at8[SERVO_EDGES];
	uint16_t *width = pl.width;
	uint16_t changed = 0;
	uint8_t n = 0;

	/* Every pulsing channel at its last place: a write changes few, and
	 * only the changed ones are placed again. */
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		uint16_t w = widths_us[ch] ? servo_cycles(widths_us[ch]) : 0;
		if (w != width[ch]) {
			width[ch] = w;
			changed |= (uint16_t)(1u << ch);
		}
		if (w) {
			uint32_t rise = slot_start[ch] + (int32_t)pl.move[ch] * SERVO_SHIFT;
			s->edge[n] = ch;
			at8[n++] = (uint16_t)(rise >> 3);
			s->edge[n] = ch | SERVO_FALL;
			at8[n++] = (uint16_t)((rise + w) >> 3);
		}
	}
	/* A changed channel whose edges come too close to another's moves:
	 * tries 0, +1, -1, +2, ... SERVO_SHIFTs from its slot (never before
	 * the frame's start), its width and period unchanged. The others were
	 * clear of each other already. */
	for (uint8_t i = 0; i < n; i += 2) {
		uint8_t ch = s->edge[i];
		if (!(changed & (1u << ch))) {
			continue;
		}
		for (int16_t k = 0; k <= 2 * SERVO_MOVES; k++) {
			int8_t move = (int8_t)((k & 1) ? -(k + 1) / 2 : k / 2);
			int32_t r = (int32_t)slot_start[ch] + (int32_t)move * SERVO_SHIFT;
			uint16_t r8 = (uint16_t)(r >> 3);
			uint16_t f8 = (uint16_t)((r + width[ch]) >> 3);
			if (r >= 0 && servo_clear_of(r8, at8, s->edge, n, ch)
			    && servo_clear_of(f8, at8, s->edge, n, ch)) {
				pl.move[ch] = move;
				at8[i] = r8;
				at8[i + 1] = f8;
				break;
			}
		}
	}
	/* Insertion sort by time: at most 32 edges. */
	for (uint8_t i = 1; i < n; i++) {
		uint8_t e = s->edge[i];
		uint16_t t = at8[i];
		uint8_t j = i;
		while (j > 0 && at8[j - 1] > t) {
			s->edge[j] = s->edge[j - 1];
			at8[j] = at8[j - 1];
			j--;
		}
		s->edge[j] = e;
		at8[j] = t;
	}
	/* Exact cycles from here on: each edge after the one before. */
	uint32_t prev = 0;
	for (uint8_t i = 0; i < n; i++) {
		uint8_t ch = s->edge[i] & SERVO_CHAN;
		uint32_t t = slot_start[ch] + (int32_t)pl.move[ch] * SERVO_SHIFT;
		if (s->edge[i] & SERVO_FALL) {
			t += width[ch];
		}
		/* Channels far apart: up to 125937 cycles between two edges. */
		if (t - prev > 0xFFFF) {
			s->edge[i] |= SERVO_LONG;
		}
		s->delta[i] = (uint16_t)(t - prev);
		prev = t;
	}
	s->n = n;
}
