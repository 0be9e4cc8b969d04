/*
 * The M32-D servo schedule (servo_plan.h), planned in the main loop.
 *
 * A write changes a few widths, so the plan is changed, not made afresh:
 * the channels that keep their width keep their place and their order in
 * the last schedule; the changed channels are placed among them one after
 * the other and put into the order. Placing looks at the edges in time
 * order from where a binary search finds the pulse's ends, and skips past
 * every edge in the way at once, instead of trying one place after the
 * other. The schedule holds each edge's cycle in the frame, so nothing
 * needs adding up.
 */
#include "drivers/servo_plan.h"

#include <string.h>

#include "firmware/flash.h"

_Static_assert(SERVO_SLOT * (SERVO_CHANNELS - 1) + SERVO_SHIFT * SERVO_MOVES + 18432UL + 1000UL
	       < SERVO_FRAME, "the last channel's longest pulse ends inside the frame");

_Static_assert(SERVO_FRAME <= 0x40000UL, "a cycle in the frame fits 18 bits (SERVO_HI)");
_Static_assert(SERVO_CHANNELS <= SERVO_CHAN + 1, "a channel fits the edge code");
_Static_assert(SERVO_SLOT >= SERVO_SHIFT * SERVO_MOVES, "only channel 0 can move before the frame");

static struct {
	int8_t move[SERVO_CHANNELS];     /* each channel's place: SERVO_SHIFTs off its slot */
	uint16_t us[SERVO_CHANNELS];     /* width as last planned; 0 = off */
} placed;

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

/* Edge `code` at cycle t. */
static servo_edge_t servo_edge(uint8_t code, uint32_t t)
{
	servo_edge_t e = { (uint8_t)(code | (uint8_t)((uint8_t)(t >> 16) << 4)), (uint16_t)t };
	return e;
}

/* How many of the edges e[0..n) are at cycle t or before (a binary
 * search). */
static uint8_t servo_count(const servo_edge_t *e, uint8_t n, int32_t t)
{
	if (t < 0) {
		return 0;
	}
	/* Bits 16-17 and 0-15 apart: byte and word compares. */
	uint8_t th = (uint8_t)((uint32_t)t >> 16);
	uint16_t tl = (uint16_t)t;
	const servo_edge_t *lo = e;
	while (n) {
		uint8_t half = n >> 1;
		const servo_edge_t *mid = lo + half;
		uint8_t h = (uint8_t)(mid->code >> 4) & 3;
		if (h < th || (h == th && mid->at <= tl)) {
			lo = mid + 1;
			n = (uint8_t)(n - half - 1);
		} else {
			n = half;
		}
	}
	return (uint8_t)(lo - e);
}

/* How far the next edge of e[0..n) from *i on in direction `dir` (1:
 * later, -1: earlier) is in the way of a pulse end at cycle `end`: 0 if it
 * keeps SERVO_GAP, else the cycles the end has to go on to keep it. Edges
 * behind the end by SERVO_GAP or more are passed for good (*i moves on).
 * *i: the next edge's index (dir 1), one more than that (dir -1). */
static int16_t servo_in_way(const servo_edge_t *e, uint8_t n, uint8_t *i, int32_t end, int8_t dir)
{
	for (;;) {
		if (dir > 0 ? *i >= n : !*i) {
			return 0;
		}
		const servo_edge_t *x = e + (dir > 0 ? *i : *i - 1);
		int32_t d = (int32_t)servo_cycle(x) - end;
		if (dir < 0) {
			d = -d;
		}
		if (d > -SERVO_GAP) {
			return d < SERVO_GAP ? (int16_t)(d + SERVO_GAP) : 0;
		}
		*i = (uint8_t)(*i + dir);
	}
}

/* The first move from 0 on in direction `dir` (its size; > SERVO_MOVES
 * if there is none) at which a pulse whose rise and fall are at b[0] and
 * b[1] at move 0 keeps SERVO_GAP from the edges e[0..n); each end starts
 * at at[] (see servo_in_way) and ends where it stopped: with the move
 * found, how many edges come before that end. An edge in the way of one end
 * pushes the move just past it; then that end looks again, and the other.
 * Edges passed stay passed, so each end looks at each edge once. */
static int16_t servo_free(const servo_edge_t *e, uint8_t n, const int32_t *b, uint8_t *at,
			  int8_t dir)
{
	int16_t m = 0;
	uint8_t k = 0, clear = 0;  /* ends found clear at this move */
	while (clear < 2 && m <= SERVO_MOVES) {
		int16_t in = servo_in_way(e, n, &at[k], b[k] + dir * (int16_t)(m * SERVO_SHIFT), dir);
		if (in) {
			m = (int16_t)(m + (uint16_t)(in + SERVO_SHIFT - 1) / SERVO_SHIFT);
			clear = 0;
		} else {
			clear++;
			k ^= 1;
		}
	}
	return m;
}

/* Channel ch (its width w changed, not 0) at the nearest place clear of the
 * edges e[0..n): 0, -1, +1, -2, ... SERVO_SHIFTs from its slot, never
 * before the frame's start; where none is clear, it stays where it was (and
 * the interrupt makes its edges as near their cycles as it can). Returns
 * its rise's cycle; at[0] and at[1]: how many edges come before its rise
 * and before its fall. */
static __attribute__((noinline)) uint32_t servo_move(const servo_edge_t *e, uint8_t n, uint8_t ch,
						     uint16_t w, uint8_t *at)
{
	int32_t b[2] = { (int32_t)slot_start[ch], (int32_t)slot_start[ch] + w };
	/* Where each end starts looking at move 0: later from the first edge
	 * not SERVO_GAP before it (at[]), earlier from the last edge not
	 * SERVO_GAP after it (down[], one more). */
	uint8_t down[2];
	for (uint8_t k = 0; k < 2; k++) {
		uint8_t i = servo_count(e, n, b[k] - SERVO_GAP);
		at[k] = i;
		while (i < n && (int32_t)servo_cycle(e + i) < b[k] + SERVO_GAP) {
			i++;
		}
		down[k] = i;
	}
	int16_t m = servo_free(e, n, b, at, 1);
	if (m && ch) {
		int16_t earlier = servo_free(e, n, b, down, -1);
		if (earlier <= m) {
			m = (int16_t)-earlier;
			at[0] = down[0];
			at[1] = down[1];
		}
	}
	uint32_t r = slot_start[ch];
	if (m >= -SERVO_MOVES && m <= SERVO_MOVES) {
		placed.move[ch] = (int8_t)m;
		r += (int16_t)(m * SERVO_SHIFT);
	} else {
		/* No clear place: where it was, among edges it may be near. */
		r += (int16_t)(placed.move[ch] * SERVO_SHIFT);
		at[0] = servo_count(e, n, (int32_t)r);
		at[1] = servo_count(e, n, (int32_t)(r + w));
	}
	return r;
}

/* Copies the edges from[0..n) whose channel has not changed to `to`
 * (which may be `from`: it never gets ahead; the edges before the first
 * one left out then stay as they are); returns where the copy ends. */
static __attribute__((noinline)) servo_edge_t *servo_keep(servo_edge_t *to, const servo_edge_t *from,
							  uint8_t n, const uint8_t *changed)
{
	if (to == from) {
		while (n && !changed[to->code & SERVO_CHAN]) {
			n--;
			to++;
		}
		from = to;
	}
	for (; n; n--, from++) {
		if (!changed[from->code & SERVO_CHAN]) {
			*to++ = *from;
		}
	}
	return to;
}

void servo_plan(servo_sched_t *s, const servo_sched_t *last, const uint16_t *widths_us)
{
	uint8_t changed[SERVO_CHANNELS];

	const uint16_t *now = widths_us;
	uint16_t *was = placed.us;
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++, now++, was++) {
		changed[ch] = *now != *was;
		*was = *now;
	}
	/* The others stay where they were, in their order. */
	servo_edge_t *e = s->edge;
	uint8_t n = (uint8_t)(servo_keep(e, last->edge, last->n, changed) - e);
	/* The changed channels in channel order, each placed among the edges
	 * now in s, then into the order: the edges after its fall move up two
	 * places, those between its edges one. */
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		if (!changed[ch] || !placed.us[ch]) {
			continue;
		}
		uint16_t w = servo_cycles(placed.us[ch]);
		uint8_t at[2];
		uint32_t r = servo_move(e, n, ch, w, at);
		uint8_t i = at[0], j = at[1];
		memmove(e + j + 2, e + j, (n - j) * sizeof *e);
		memmove(e + i + 1, e + i, (j - i) * sizeof *e);
		e[i] = servo_edge(ch, r);
		e[j + 1] = servo_edge((uint8_t)(ch | SERVO_FALL), r + w);
		n = (uint8_t)(n + 2);
	}
	s->n = n;
}
