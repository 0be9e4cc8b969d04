/*
 * The M32-D servo planner (drivers/servo_plan.c) on the host, step by step
 * against a model of what docs/registers.md ("Servos") and servo_plan.h
 * promise: every pulsing channel once a frame with its width, channel n
 * starting n x 8191 cycles into the frame unless it must move, moves in
 * 32-cycle units, at most 96 either way, never before the frame's start,
 * the nearest place first (earlier before later at the same distance), no
 * edge within 400 cycles of another channel's edge, channels whose width
 * stays the same never move; changed channels are placed in channel order,
 * each clear of the channels placed before it. Prints "servo plan: N passed, N failed".
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "drivers/servo_plan.h"

#define NCH SERVO_CHANNELS
#define SLOT 8191L
#define SHIFT 32L
#define MOVES 96
#define GAP 400
#define FRAME 147456L

static int passed, failed;

static void check(int ok, const char *what, long step)
{
	if (ok) {
		passed++;
	} else {
		failed++;
		if (failed <= 20) {
			printf("FAIL servo plan, step %ld: %s\n", step, what);
		}
	}
}

/* Cycles for a width: us x 7.3728 to the nearest cycle, as a 16.16
 * product (the planner's arithmetic; checked below against the exact
 * product: at most 0.51 cycles off). */
static long cycles(unsigned us)
{
	return us ? (long)(((unsigned long)us * 483184UL + 32768UL) >> 16) : 0;
}

/* What the model knows of the last plan: each channel's width (cycles, 0 =
 * off) and move (SHIFT units; an off channel keeps its last one). */
static long m_width[NCH];
static int m_move[NCH];

static long rise_of(int ch, int move)
{
	return SLOT * ch + SHIFT * move;
}

/* Whether channel ch at `move` keeps GAP from every channel in `with`. */
static int clear(int ch, int move, const int *with)
{
	long r = rise_of(ch, move), f = r + m_width[ch];
	for (int c = 0; c < NCH; c++) {
		if (!with[c] || c == ch) {
			continue;
		}
		long cr = rise_of(c, m_move[c]), cf = cr + m_width[c];
		long mine[2] = { r, f }, theirs[2] = { cr, cf };
		for (int i = 0; i < 2; i++) {
			for (int j = 0; j < 2; j++) {
				if (labs(mine[i] - theirs[j]) < GAP) {
					return 0;
				}
			}
		}
	}
	return 1;
}

static long fallbacks, moves_seen;

/* The model's plan of `us`: channels whose width changes are placed in
 * channel order, each at the nearest clear place (0, -1, +1, -2, ...) among
 * the channels that keep theirs and those placed before it; a channel with
 * no clear place keeps its last one. `unplaced` gets those channels. */
static void model(const uint16_t *us, int *unplaced)
{
	int changed[NCH], placed[NCH];
	for (int ch = 0; ch < NCH; ch++) {
		long w = cycles(us[ch]);
		changed[ch] = w != m_width[ch];
		m_width[ch] = w;
		placed[ch] = w && !changed[ch];
		unplaced[ch] = 0;
	}
	for (int ch = 0; ch < NCH; ch++) {
		if (!changed[ch] || !m_width[ch]) {
			continue;
		}
		int k;
		for (k = 0; k <= 2 * MOVES; k++) {
			int move = (k & 1) ? -(k + 1) / 2 : k / 2;
			if (rise_of(ch, move) >= 0 && clear(ch, move, placed)) {
				m_move[ch] = move;
				moves_seen += move != 0;
				break;
			}
		}
		if (k > 2 * MOVES) {
			unplaced[ch] = 1;
			fallbacks++;
		}
		placed[ch] = 1;
	}
}

/* Decodes a schedule into each channel's rise and fall (-1: none) and checks
 * its form: times in order, each pulsing channel once, nothing else. */
static void decode(const servo_sched_t *s, long *rise, long *fall, long step)
{
	long prev = -1;
	int ok_order = 1, ok_code = 1;
	for (int ch = 0; ch < NCH; ch++) {
		rise[ch] = fall[ch] = -1;
	}
	for (int i = 0; i < s->n; i++) {
		uint8_t e = s->edge[i].code;
		int ch = e & SERVO_CHAN;
		long t = (long)servo_cycle(&s->edge[i]);
		ok_order &= t == ((long)((e >> 4) & 3) << 16 | s->edge[i].at) && t > prev;
		prev = t;
		long *slot = (e & SERVO_FALL) ? &fall[ch] : &rise[ch];
		ok_code &= ch < NCH && !(e & (uint8_t)~(SERVO_CHAN | SERVO_FALL | SERVO_HI))
			   && *slot < 0;
		if (ch < NCH) {
			*slot = t;
		}
	}
	check(ok_order, "edges in time order", step);
	check(ok_code, "each edge once, a known code", step);
	check(prev < FRAME, "the last edge inside the frame", step);
}

/* The firmware's two buffers: the planner plans into the one the interrupt
 * is not running, from the last plan: that buffer itself while it waits to
 * be taken over, else the running one; and the widths the last plan had. */
static servo_sched_t buf[2];
static int running;
static uint16_t last_us[NCH];

/* One write of `us` (all channels); the planner must place as the model
 * does. `taken`: the last plan was taken over before this write. */
static void step(const uint16_t *us, int taken, long n)
{
	int unplaced[NCH];
	long rise[NCH], fall[NCH];
	char what[200];

	model(us, unplaced);
	if (taken) {
		running ^= 1;
	}
	servo_sched_t *s = &buf[running ^ 1];
	servo_plan(s, taken ? &buf[running] : s, us);
	memcpy(last_us, us, sizeof last_us);
	decode(s, rise, fall, n);
	int count = 0, ok_width = 1, ok_move = 1, ok_same = 1;
	for (int ch = 0; ch < NCH; ch++) {
		if (!us[ch]) {
			ok_width &= rise[ch] < 0 && fall[ch] < 0;
			continue;
		}
		count++;
		ok_width &= rise[ch] >= 0 && fall[ch] - rise[ch] == m_width[ch];
		long off = rise[ch] - SLOT * ch;
		ok_move &= off % SHIFT == 0 && labs(off / SHIFT) <= MOVES && rise[ch] >= 0;
		if (rise[ch] != rise_of(ch, m_move[ch])) {
			ok_same = 0;
			snprintf(what, sizeof what, "channel %d at %ld, the model has %ld", ch,
				 rise[ch], rise_of(ch, m_move[ch]));
		}
	}
	check(s->n == 2 * count, "two edges a pulsing channel", n);
	check(ok_width, "widths as planned, off channels silent", n);
	check(ok_move, "moves in 32-cycle units, at most 96, not before the frame", n);
	check(ok_same, ok_same ? "placed as the model" : what, n);
	/* Edges of different channels GAP apart, unless one of the two had no
	 * clear place. */
	int ok_gap = 1;
	for (int a = 0; a < NCH; a++) {
		for (int b = a + 1; b < NCH; b++) {
			if (!us[a] || !us[b] || unplaced[a] || unplaced[b]) {
				continue;
			}
			long ta[2] = { rise[a], fall[a] }, tb[2] = { rise[b], fall[b] };
			for (int i = 0; i < 2; i++) {
				for (int j = 0; j < 2; j++) {
					if (labs(ta[i] - tb[j]) < GAP) {
						ok_gap = 0;
						snprintf(what, sizeof what, "channels %d and %d too close", a, b);
					}
				}
			}
		}
	}
	check(ok_gap, ok_gap ? "edges apart" : what, n);
}

static unsigned long rng = 12345;

static unsigned rnd(unsigned n)
{
	rng = rng * 6364136223846793005UL + 1442695040888963407UL;
	return (unsigned)((rng >> 33) % n);
}

/* A width that often puts a fall near another channel's start. */
static uint16_t some_width(void)
{
	switch (rnd(6)) {
	case 0:
		return 0;
	case 1:
		return (uint16_t)(1111 - 60 + rnd(121));
	case 2:
		return (uint16_t)(2222 - 60 + rnd(121));
	default:
		return (uint16_t)(500 + rnd(2001));
	}
}

int main(void)
{
	uint16_t us[NCH];
	long n = 0;

	/* The width: within 0.51 cycles of us x 7.3728 over the whole range. */
	int ok = 1;
	for (unsigned u = 500; u <= 2500; u++) {
		ok &= labs(cycles(u) * 10000 - (long)u * 73728) <= 5100;
	}
	check(ok, "cycles(us) within 0.51 cycles", 0);

	/* Every channel at 1000 us: all at their slots. */
	for (int ch = 0; ch < NCH; ch++) {
		us[ch] = 1000;
	}
	step(us, 1, ++n);
	check(moves_seen == 0, "16 x 1000 us: nobody moves", n);
	/* One channel ends where the next starts: the one written moves. */
	us[6] = 1111;
	step(us, 1, ++n);
	check(m_move[6] != 0 && m_move[7] == 0, "channel 6 moves off channel 7's start", n);
	memset(us, 0, sizeof us);
	step(us, 1, ++n);
	check(buf[running ^ 1].n == 0, "all off: an empty schedule", n);
	/* Channel 10 starts 81910 cycles into the frame: more than 16 bits. */
	us[1] = 1096;
	us[10] = 1500;
	step(us, 1, ++n);
	const servo_sched_t *s = &buf[running ^ 1];
	check(s->n == 4 && s->edge[2].code == (0x10 | 10) && s->edge[2].at == 81910 - 65536,
	      "cycles past 65535 kept", n);
	/* Two channels written together where channel 5 ends 81 cycles before
	 * channel 6 starts: 5, placed first, stays; 6 moves. */
	memset(us, 0, sizeof us);
	step(us, 1, ++n);
	us[5] = 1100;
	us[6] = 1200;
	step(us, 0, ++n);
	check(m_move[5] == 0 && m_move[6] != 0, "channel 6 moves off channel 5's fall", n);

	/* Random writes: one triple mostly, some of several, some of all 16. */
	for (int i = 0; i < 20000; i++) {
		unsigned kind = rnd(10), count = kind < 7 ? 1 : kind < 9 ? 2 + rnd(6) : NCH;
		for (unsigned k = 0; k < count; k++) {
			unsigned ch = count == NCH ? k : rnd(NCH);
			us[ch] = some_width();
		}
		step(us, rnd(2), ++n);
	}
	printf("servo plan: %d passed, %d failed (%ld channels moved, %ld without a place)\n",
	       passed, failed, moves_seen, fallbacks);
	return failed ? 1 : 0;
}
