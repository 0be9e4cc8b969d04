/*
 * The M32-D servo schedule (servo_plan.h), planned in the main loop.
 *
 * A write changes a few widths, so the plan is changed, not made afresh:
 * the channels that keep their width keep their place and their order in
 * the last schedule; the changed channels are placed one after the other
 * and their edges put into the order.
 * A channel can only come near the edges of the three channels either side
 * of it (a pulse is at most 2.25 slots long and moves at most 3072
 * cycles), so placing one looks at those few edges alone, from the
 * channels' places, not the schedule: each edge near enough to matter rules
 * out a range of moves, and the nearest move outside all of them is found
 * by skipping past each range in the way. Distances are cycles modulo 2^16
 * (16-bit sums: the ones that matter are under 3472, the others never come
 * within 2^16 - 3472 of 0). The schedule holds each edge's cycle in the
 * frame, so nothing needs adding up.
 */
#include "drivers/servo_plan.h"

#include <string.h>

#include "firmware/flash.h"

_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES + 18432UL + 1000UL
	       < SERVO_FRAME, "the last channel's longest pulse ends inside the frame");

_Static_assert(SERVO_FRAME <= 0x40000UL, "a cycle in the frame fits 18 bits (SERVO_HI)");
_Static_assert(SERVO_CHANNELS <= SERVO_CHAN + 1, "a channel fits the edge code");
_Static_assert(SERVO_SLOT >= SERVO_SHIFT * SERVO_MOVES, "only channel 0 can move before the frame");

/* The most a channel moves, cycles, and the distance from its ends (at
 * move 0) within which another edge can be in its way. */
#define SERVO_REACH ((int16_t)(SERVO_SHIFT * SERVO_MOVES))
#define SERVO_NEAR_ENOUGH (SERVO_REACH + SERVO_GAP)
/* The longest pulse (2500 us) in cycles: only channels NEIGHBOURS either
 * side can come near. */
#define SERVO_LONGEST 18432UL
#define SERVO_NEIGHBOURS 3
_Static_assert(SERVO_SLOT - SERVO_REACH >= SERVO_NEAR_ENOUGH, "two rises are never near");
_Static_assert(SERVO_SLOT * (SERVO_NEIGHBOURS + 1) > SERVO_LONGEST + 2UL * SERVO_NEAR_ENOUGH,
	       "a channel NEIGHBOURS + 1 away is never in the way");
_Static_assert(SERVO_SLOT * (SERVO_NEIGHBOURS + 1) + SERVO_LONGEST + 2UL * SERVO_REACH
	       < 65536UL - SERVO_NEAR_ENOUGH, "16-bit distances to the neighbours are exact");

static struct {
	int8_t move[SERVO_CHANNELS];     /* each channel's place: SERVO_SHIFTs off its slot */
	uint16_t w[SERVO_CHANNELS];      /* width in cycles as last marked; 0 = off; with
					  * SERVO_MARK: changed, not placed yet */
} placed;
/* A width in cycles is at most SERVO_LONGEST: bit 15 is free for the mark. */
#define SERVO_MARK 0x8000u
_Static_assert(SERVO_LONGEST < SERVO_MARK, "a width in cycles leaves bit 15 free");

/* Cycles for a width in microseconds, rounded to the nearest: us * 7.3728
 * as a 16.16 fixed-point product (a division took 600 cycles a channel). */
#define SERVO_CYCLES_PER_US_Q16 ((uint32_t)((F_CPU * 65536ULL + 500000ULL) / 1000000ULL))
static uint16_t servo_cycles(uint16_t us)
{
	/* The whole cycles apart: a 16 x 16-bit product is all that is left. */
	return (uint16_t)(us * (uint16_t)(SERVO_CYCLES_PER_US_Q16 >> 16)
			  + (((uint32_t)us * (uint16_t)SERVO_CYCLES_PER_US_Q16 + 32768UL) >> 16));
}

/* The least move in cycles from 0 on (a whole number of SERVO_SHIFTs) that
 * keeps SERVO_GAP from every edge d[0..n) (each edge's distance from the
 * pulse's end it is compared with, at move 0); more than SERVO_REACH if
 * there is none. An edge in the way pushes the move just past it; the
 * edges are looked at in turn until n in a row are clear. */
static int16_t servo_clear(const int16_t *d, uint8_t n)
{
	int16_t t = 0;
	uint8_t i = 0, ok = 0;
	while (ok < n && t <= SERVO_REACH) {
		int16_t x = d[i];
		if (x - SERVO_GAP < t && t < x + SERVO_GAP) {
			t = (int16_t)((x + SERVO_GAP + SERVO_SHIFT - 1) & -SERVO_SHIFT);
			ok = 0;
		} else {
			ok++;
		}
		if (++i == n) {
			i = 0;
		}
	}
	return t;
}

/* Channel ch (its width changed, not 0) at the nearest place clear of the
 * channels placed (those SERVO_MARK still marks are still to place): 0, -1, +1, -2, ...
 * SERVO_SHIFTs from its slot, never before the frame's start; where none
 * is clear, it stays where it was (and the interrupt makes its edges as
 * near their cycles as it can). */
/* Adds distance x to the edges at `end` if it is near enough to matter. */
static inline int16_t *servo_near(int16_t *end, uint16_t x)
{
	if ((int16_t)x > -SERVO_NEAR_ENOUGH && (int16_t)x < SERVO_NEAR_ENOUGH) {
		*end++ = (int16_t)x;
	}
	return end;
}

static __attribute__((noinline)) void servo_place(uint8_t ch)
{
	/* Each neighbour's edges as distances from this channel's rise at
	 * move 0; of those, a channel before it can only come near its rise
	 * and fall with its own fall, one after with its rise and fall, each
	 * only near this channel's fall (rises are SERVO_SLOT apart, a pulse
	 * is at least 500 us). */
	/* static (scratch, in .noinit: not cleared at start-up): each
	 * edge's place a fixed address, not a sum with the stack frame's
	 * (10 bytes) */
	static int16_t d[2 * 2 * SERVO_NEIGHBOURS] ORFA_NOINIT;
	int16_t *end = d;
	uint16_t w = placed.w[ch];
	for (int8_t k = -SERVO_NEIGHBOURS; k <= SERVO_NEIGHBOURS; k++) {
		uint8_t c = (uint8_t)(ch + k);
		if (!k || c >= SERVO_CHANNELS) {
			continue;
		}
		uint16_t cw = placed.w[c];
		if (!cw || (cw & SERVO_MARK)) {
			continue;  /* off, or changed and still to place (after ch) */
		}
		uint16_t x = (uint16_t)(k * (int16_t)SERVO_SLOT + placed.move[c] * SERVO_SHIFT);
		uint16_t y = (uint16_t)(x + cw);
		end = servo_near(end, (uint16_t)(y - w));
		end = servo_near(end, k < 0 ? y : (uint16_t)(x - w));
	}
	uint8_t n = (uint8_t)(end - d);
	if (!n) {
		placed.move[ch] = 0;  /* nothing near: its slot */
		return;
	}
	int16_t t = servo_clear(d, n);
	if (t && ch) {
		for (uint8_t i = 0; i < n; i++) {
			d[i] = (int16_t)-d[i];
		}
		int16_t earlier = servo_clear(d, n);
		if (earlier <= t) {
			t = (int16_t)-earlier;
		}
	}
	if (t >= -SERVO_REACH && t <= SERVO_REACH) {
		placed.move[ch] = (int8_t)(t / SERVO_SHIFT);
	}
}

/* Edge `code` at cycle t put in the place of the edge at p, then moved
 * into the order of the edges first..end (all in order but for p): those
 * it passes move a place towards where it was (it goes after one at the
 * same cycle). An edge moves little where it changes little; one put at
 * the end goes back past a few falls where the channels come in order (a
 * rise comes after the rises before it, a fall before those after it). */
static __attribute__((noinline)) servo_edge_t *servo_put(servo_edge_t *first, servo_edge_t *end,
							 servo_edge_t *p, uint8_t code, uint32_t t)
{
	uint8_t hi = (uint8_t)((uint8_t)(t >> 16) << 4);
	uint16_t at = (uint16_t)t;
	while (p != first) {
		servo_edge_t *q = p - 1;
		uint8_t qh = q->code & SERVO_HI;
		if (qh < hi || (qh == hi && q->at <= at)) {
			break;
		}
		*p = *q;
		p = q;
	}
	while (p + 1 != end) {
		servo_edge_t *q = p + 1;
		uint8_t qh = q->code & SERVO_HI;
		if (qh > hi || (qh == hi && q->at > at)) {
			break;
		}
		*p = *q;
		p = q;
	}
	p->code = (uint8_t)(code | hi);
	p->at = at;
	return p;
}

/* The first edge of p..end with code `code` (cycle bits aside); end if
 * none. */
static __attribute__((noinline)) servo_edge_t *servo_find(servo_edge_t *p, const servo_edge_t *end, uint8_t code)
{
	while (p != end && (p->code & (uint8_t)~SERVO_HI) != code) {
		p++;
	}
	return p;
}

/* Takes the edge at p out of first..end; returns the new end. */
static __attribute__((noinline)) servo_edge_t *servo_drop(servo_edge_t *p, servo_edge_t *end)
{
	for (end--; p != end; p++) {
		*p = p[1];
	}
	return end;
}

__attribute__((noinline))
void servo_plan(servo_sched_t *s, const servo_sched_t *last, const uint16_t *widths_us)
{
	/* The channels whose width in cycles is not the one last planned:
	 * marked, with their new width. */
	uint16_t *w = placed.w;
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++, w++) {
		uint16_t us = widths_us[ch];
		uint16_t cw = us ? servo_cycles(us) : 0;
		if (cw != *w) {
			*w = (uint16_t)(cw | SERVO_MARK);
		}
	}
	/* The last schedule, then each changed channel in channel order: placed
	 * clear of those placed before it, its edges moved to their new cycles
	 * (or taken out, or put in). The order holds throughout: an edge not
	 * moved yet is still at its last cycle. The rises stay in channel
	 * order, so a channel's rise is after the one changed before it. */
	servo_edge_t *first = s->edge, *end = first + last->n;
	if (last != s) {
		memcpy(first, last->edge, (size_t)last->n * sizeof *first);
	}
	servo_edge_t *from = first;  /* no changed channel's rise before this */
	uint32_t slot = 0;           /* the channel's slot start */
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++, slot += SERVO_SLOT) {
		uint16_t cw = placed.w[ch];
		if (!(cw & SERVO_MARK)) {
			continue;
		}
		cw = (uint16_t)(cw & ~SERVO_MARK);
		placed.w[ch] = cw;  /* placed now: no longer marked */
		/* Its fall is after its rise, and stays so however the rise moves
		 * (the edges it passes move towards where it was). */
		servo_edge_t *rise = servo_find(from, end, ch);
		if (rise != end && !cw) {
			end = servo_drop(rise, end);
			end = servo_drop(servo_find(rise, end, (uint8_t)(ch | SERVO_FALL)), end);
			from = rise;
			continue;
		}
		if (!cw) {
			continue;
		}
		int8_t move = placed.move[ch];
		servo_place(ch);
		uint32_t r = slot + (int16_t)(placed.move[ch] * SERVO_SHIFT);
		servo_edge_t *fall;
		if (rise == end) {
			/* It starts: both edges put in at the end. */
			rise = servo_put(first, ++end, rise, ch, r);
			fall = end++;
		} else {
			/* A rise stays where it was unless its channel moves. */
			servo_edge_t *was = rise;
			if (placed.move[ch] != move) {
				rise = servo_put(first, end, rise, ch, r);
			}
			fall = servo_find(was < rise ? was : rise, end, (uint8_t)(ch | SERVO_FALL));
		}
		servo_put(first, end, fall, (uint8_t)(ch | SERVO_FALL), r + cw);
		from = rise + 1;
	}
	s->n = (uint8_t)(end - first);
}
