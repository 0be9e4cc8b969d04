/*
 * The M32-D servo schedule (servo_plan.h), planned in the main loop.
 *
 * A write changes a few widths, so the plan is changed, not made afresh:
 * the channels that keep their width keep their place and their order in
 * the last schedule; each changed channel is taken out, placed among the
 * others and put back in order. Placing looks at the edges in time order
 * and skips past every edge in the way at once, instead of trying one
 * place after the other.
 */
#include "drivers/servo_plan.h"

#include "firmware/flash.h"

_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES + 18432UL + 1000UL
	       < SERVO_FRAME, "the last channel's longest pulse ends inside the frame");

/* No two edges of a frame are 131072 cycles apart (SERVO_LONG covers 17
 * bits): the latest start is the last channel's, moved late. */
_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES < 0x20000UL,
	       "a delta fits 16 bits and SERVO_LONG");
_Static_assert(SERVO_CHANNELS <= SERVO_CHAN + 1, "a channel fits the edge code");
_Static_assert(SERVO_CHANNELS <= 16, "a channel mask fits 16 bits");
_Static_assert(SERVO_SLOT >= SERVO_SHIFT * SERVO_MOVES, "only channel 0 can move before the frame");

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
	/* The whole cycles apart: a 16 x 16-bit product is all that is left. */
	return (uint16_t)(us * (uint16_t)(SERVO_CYCLES_PER_US_Q16 >> 16)
			  + (((uint32_t)us * (uint16_t)SERVO_CYCLES_PER_US_Q16 + 32768UL) >> 16));
}

/* An edge's cycle in the frame, from its channel's place and width. */
static uint32_t servo_time(uint8_t e)
{
	uint8_t ch = e & SERVO_CHAN;
	uint32_t t = slot_start[ch] + (int16_t)(pl.move[ch] * SERVO_SHIFT);
	if (e & SERVO_FALL) {
		t += pl.width[ch];
	}
	return t;
}

/* Edges are spaced in 8-cycle units, 16 bits (a frame is 18432 of them):
 * two edges at least SERVO_GAP8 apart so counted are 393 cycles or more
 * apart. A move is 4 units, so a pulse's rise at move m is at r8 + 4m. */
#define SERVO_GAP8 (SERVO_GAP / 8)
_Static_assert(SERVO_SHIFT == 32, "a move is 4 units of 8 cycles");

/* The first move from 0 on in direction `dir` (1: later, -1: earlier; the
 * move's size is returned, > SERVO_MOVES if there is none) at which a
 * pulse whose rise and fall are at b8[0] and b8[1] at move 0 keeps
 * SERVO_GAP8 from every edge in at8[0..n), sorted. For dir -1 every time
 * is mirrored (negated, the edges taken from the last): the same search.
 * An edge that blocks one end pushes the move to just past it; edges passed
 * stay passed, so each end looks at each edge once. */
static int16_t servo_free(const int16_t *b8, const uint16_t *at8, uint8_t n, int8_t dir)
{
	uint8_t next[2] = { 0, 0 };  /* each end's first edge not yet passed */
	int16_t m = 0;
	for (;;) {
		uint8_t k;
		int16_t a = 0;
		for (k = 0; k < 2; k++) {
			int16_t b = (int16_t)(dir * b8[k]);
			int16_t t = (int16_t)(b + 4 * m);
			for (; next[k] < n; next[k]++) {
				a = (int16_t)(dir * (int16_t)at8[dir > 0 ? next[k] : n - 1 - next[k]]);
				if (a > t - SERVO_GAP8) {
					break;
				}
			}
			if (next[k] < n && a < t + SERVO_GAP8) {
				/* Blocked: the first move with b + 4m >= a + SERVO_GAP8. */
				m = (int16_t)((a + SERVO_GAP8 - b + 3) >> 2);
				break;
			}
		}
		if (k == 2 || m > SERVO_MOVES) {
			return m;
		}
	}
}

/* Puts edge e into s->edge[0..n) and at8 (its time in 8-cycle units) in
 * time order; returns the new count. */
static uint8_t servo_insert(servo_sched_t *s, uint16_t *at8, uint8_t n, uint8_t e)
{
	uint32_t t = servo_time(e);
	uint16_t t8 = (uint16_t)(t >> 3);
	uint8_t i = n;
	while (i && (at8[i - 1] > t8 || (at8[i - 1] == t8 && servo_time(s->edge[i - 1]) > t))) {
		s->edge[i] = s->edge[i - 1];
		at8[i] = at8[i - 1];
		i--;
	}
	s->edge[i] = e;
	at8[i] = t8;
	return (uint8_t)(n + 1);
}

void servo_plan(servo_sched_t *s, const servo_sched_t *last, const uint16_t *widths_us)
{
	uint16_t at8[SERVO_EDGES];
	uint16_t changed = 0;
	uint8_t n = 0;

	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		uint16_t w = widths_us[ch] ? servo_cycles(widths_us[ch]) : 0;
		if (w != pl.width[ch]) {
			pl.width[ch] = w;
			changed |= (uint16_t)(1u << ch);
		}
	}
	/* The others stay where they were, in their order. */
	for (uint8_t i = 0; i < last->n; i++) {
		uint8_t e = last->edge[i] & (uint8_t)~SERVO_LONG;
		if (!(changed & (1u << (e & SERVO_CHAN)))) {
			s->edge[n] = e;
			at8[n++] = (uint16_t)(servo_time(e) >> 3);
		}
	}
	/* Each changed channel, in channel order, at the nearest place clear of
	 * those placed: 0, -1, +1, -2, ... SERVO_SHIFTs from its slot, never
	 * before the frame's start. Where none is clear, it stays where it was
	 * (and the interrupt makes its edges as near their cycles as it can). */
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		uint16_t w = pl.width[ch];
		if (!(changed & (1u << ch)) || !w) {
			continue;
		}
		uint32_t r = slot_start[ch];
		int16_t b8[2] = { (int16_t)(r >> 3), (int16_t)((r + w) >> 3) };
		int16_t m = servo_free(b8, at8, n, 1);
		if (m && ch) {
			int16_t earlier = servo_free(b8, at8, n, -1);
			if (earlier <= m) {
				m = (int16_t)-earlier;
			}
		}
		if (m >= -SERVO_MOVES && m <= SERVO_MOVES) {
			pl.move[ch] = (int8_t)m;
		}
		n = servo_insert(s, at8, n, ch);
		n = servo_insert(s, at8, n, (uint8_t)(ch | SERVO_FALL));
	}
	/* Exact cycles from here on: each edge after the one before. */
	uint32_t prev = 0;
	for (uint8_t i = 0; i < n; i++) {
		uint32_t t = servo_time(s->edge[i]);
		/* Channels far apart: up to 125937 cycles between two edges. */
		if (t - prev > 0xFFFF) {
			s->edge[i] |= SERVO_LONG;
		}
		s->delta[i] = (uint16_t)(t - prev);
		prev = t;
	}
	s->n = n;
}
