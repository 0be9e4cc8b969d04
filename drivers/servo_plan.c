/*
 * The M32-D servo schedule (servo_plan.h), planned in the main loop.
 *
 * A write changes a few widths, so the plan is changed, not made afresh:
 * the channels that keep their width keep their place and their order in
 * the last schedule (their times are its deltas added up); each changed
 * channel is taken out, placed among the others and put back in order.
 * Placing looks at the edges in time order and skips past every edge in the
 * way at once, instead of trying one place after the other.
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

/* The first move from 0 on in direction `dir` (1: later, -1: earlier; the
 * move's size is returned, > SERVO_MOVES if there is none) at which a pulse
 * whose rise and fall are at b[0] and b[1] at move 0 keeps SERVO_GAP cycles
 * from every edge at at[0..n), sorted. For dir -1 every time is mirrored
 * (the caller negates b, the edges are taken from the last, negated): the
 * same search. An edge that blocks one end pushes the move just past it;
 * edges passed stay passed, so each end looks at each edge once. */
static int16_t servo_free(const int32_t *b, const int32_t *at, uint8_t n, int8_t dir)
{
	const int32_t *next[2];  /* each end's first edge not yet passed */
	const int32_t *stop = dir > 0 ? at + n : at - 1;
	next[0] = next[1] = dir > 0 ? at : at + n - 1;
	int16_t m = 0;
	uint8_t k = 0, clear = 0;  /* ends found clear at this move */
	do {
		int32_t end = b[k] + (int16_t)(m * SERVO_SHIFT);
		const int32_t *q = next[k];
		int16_t in = 0;  /* how far the edge in the way reaches past the end */
		for (; q != stop; q += dir) {
			int32_t d = (dir > 0 ? *q : -*q) - end;
			if (d > -SERVO_GAP) {
				if (d < SERVO_GAP) {
					in = (int16_t)(d + SERVO_GAP);
				}
				break;
			}
		}
		next[k] = q;
		if (in) {
			/* The first move that takes this end SERVO_GAP past it;
			 * then this end again (the next edge), and the other. */
			m = (int16_t)(m + (uint16_t)(in + SERVO_SHIFT - 1) / SERVO_SHIFT);
			clear = 0;
		} else {
			clear++;
			k ^= 1;
		}
	} while (clear < 2 && m <= SERVO_MOVES);
	return m;
}

/* Channel ch (its width changed, not 0) at the nearest place clear of the
 * edges at[0..n) of s: 0, -1, +1, -2, ... SERVO_SHIFTs from its slot, never
 * before the frame's start; where none is clear, it stays where it was (and
 * the interrupt makes its edges as near their cycles as it can). Its two
 * edges go into the order; returns the new count. (A function of its own:
 * a small frame keeps avr-gcc's locals in reach of its pointer registers.) */
static __attribute__((noinline)) uint8_t servo_place(servo_sched_t *s, int32_t *at, uint8_t n,
						     uint8_t ch)
{
	uint16_t w = pl.width[ch];
	int32_t b[2] = { (int32_t)slot_start[ch], (int32_t)slot_start[ch] + w };
	int16_t m = servo_free(b, at, n, 1);
	if (m && ch) {
		b[0] = -b[0];
		b[1] = -b[1];
		int16_t earlier = servo_free(b, at, n, -1);
		if (earlier <= m) {
			m = (int16_t)-earlier;
		}
	}
	if (m >= -SERVO_MOVES && m <= SERVO_MOVES) {
		pl.move[ch] = (int8_t)m;
	}
	/* Its fall, then its rise into the order from the end: the edges after
	 * the fall move up two places, those between one. */
	int32_t r = (int32_t)slot_start[ch] + (int16_t)(pl.move[ch] * SERVO_SHIFT);
	int32_t t = r + w;
	uint8_t code = (uint8_t)(ch | SERVO_FALL);
	int32_t *from = at + n, *to = at + n + 2;
	uint8_t *efrom = s->edge + n, *eto = s->edge + n + 2;
	for (;;) {
		while (from != at && from[-1] > t) {
			*--to = *--from;
			*--eto = *--efrom;
		}
		*--to = t;
		*--eto = code;
		if (code == ch) {
			return (uint8_t)(n + 2);
		}
		code = ch;
		t = r;
	}
}

void servo_plan(servo_sched_t *s, const servo_sched_t *last, const uint16_t *widths_us)
{
	int32_t at[SERVO_EDGES];  /* each edge's cycle in the frame */
	uint8_t changed[SERVO_CHANNELS];
	uint8_t n;

	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		uint16_t w = widths_us[ch] ? servo_cycles(widths_us[ch]) : 0;
		changed[ch] = w != pl.width[ch];
		pl.width[ch] = w;
	}
	/* The others stay where they were, in their order; their cycles are
	 * the last plan's deltas added up. */
	{
		const uint8_t *e = last->edge;
		const uint16_t *d = last->delta;
		uint8_t *to = s->edge;
		int32_t *t = at;
		int32_t now = 0;
		for (uint8_t i = last->n; i; i--) {
			uint8_t code = *e++;
			now += *d++;
			if (code & SERVO_LONG) {
				now += 0x10000L;
				code &= (uint8_t)~SERVO_LONG;
			}
			if (!changed[code & SERVO_CHAN]) {
				*to++ = code;
				*t++ = now;
			}
		}
		n = (uint8_t)(to - s->edge);
	}
	/* The changed channels, in channel order, each clear of those placed. */
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		if (changed[ch] && pl.width[ch]) {
			n = servo_place(s, at, n, ch);
		}
	}
	/* Each edge's cycles after the one before. Channels far apart: up to
	 * 125937 cycles between two edges. */
	{
		uint8_t *e = s->edge;
		uint16_t *d = s->delta;
		const int32_t *t = at;
		int32_t before = 0;
		for (uint8_t i = n; i; i--) {
			uint32_t gap = (uint32_t)(*t - before);
			before = *t++;
			if (gap > 0xFFFF) {
				*e |= SERVO_LONG;
			}
			e++;
			*d++ = (uint16_t)gap;
		}
	}
	s->n = n;
}
