/*
 * world.c: the lock-step loop over the boards.
 */
#include <string.h>

#include "harness/world.h"

#include "harness/profile.h"

void world_init(world_t *w)
{
	memset(w, 0, sizeof(*w));
	w->dead = -1;
	twi_bus_init(&w->bus, &w->trace);
}

const char *world_add_part(world_t *w, const part_kind_t *kind, uint8_t addr8, const char *opts)
{
	part_env_t env = { .bus = &w->bus, .hz = SIM_FREQUENCY, .addr8 = addr8, .opts = opts };
	const char *err = "too many parts";
	void *self;

	if (w->parts.n == PART_LIST_MAX) {
		return err;
	}
	self = part_make(kind, &env, &err);
	if (!self) {
		return err;
	}
	part_list_add(&w->parts, kind, self, addr8);
	((twi_dev_t *)self)->name = kind->name;	/* its first member: the twi_dev_t */
	twi_bus_attach(&w->bus, self);
	return NULL;
}

static int world_state_dead(int state)
{
	return state == cpu_Done || state == cpu_Crashed;
}

/* Have BYTES bus bytes come since the count was FROM (world_run)? */
static int world_bytes_came(const world_t *w, uint32_t from, uint32_t bytes)
{
	return bytes && w->bus.bytes - from >= bytes;
}

/* One board alone needs no lock-step: it runs to TARGET at once, parked
 * (park.h) wherever it idles, tried every WORLD_QUANTUM cycles. Waiting for
 * BYTES, it runs a quantum at a time, parked or not, and stops after the
 * one they came in. */
static int world_run_one(world_t *w, uint64_t target, uint32_t bytes)
{
	avr_t *avr = w->boards[0]->avr;
	park_t *park = &w->park[0];
	uint32_t from = w->bus.bytes;

	while (avr->cycle < target && !world_bytes_came(w, from, bytes)) {
		uint64_t end = avr->cycle + WORLD_QUANTUM;
		int state;

		if ((w->no_park && !bytes) || end > target) {
			end = target;
		}
		if (park->parked && park_stays(park, avr, bytes ? end : target)) {
			continue;
		}
		state = park_run(park, avr, end, !w->no_park && !profile_boards);
		if (world_state_dead(state)) {
			w->dead = 0;
			w->dead_state = state;
			return 1;
		}
	}
	if (park->parked) {
		park_leave(park, avr);
	}
	w->now = avr->cycle;
	return 0;
}

/* Every parked board leaves its loop: between runs the boards are as
 * lock-step left them, for the control interface and the next run. */
static void world_unpark(world_t *w)
{
	for (int i = 0; i < w->nboards; i++) {
		if (w->park[i].parked) {
			park_leave(&w->park[i], w->boards[i]->avr);
		}
	}
}

/* Every board parked with nothing pending: no board runs an instruction
 * before the first timer any of them has, so nothing reaches any of them
 * from another, and every quantum until then only moves their cycles.
 * Those quanta are done at once: each board goes to the first boundary at
 * or past the last of them (a boundary is at most 4 cycles past an end:
 * the margin keeps it before every board's first timer). */
#define WORLD_SKIP_MARGIN 8

static void world_skip(world_t *w, uint64_t target)
{
	uint64_t horizon = target, end;

	for (int i = 0; i < w->nboards; i++) {
		const park_t *park = &w->park[i];

		if (!park_quiet(park, w->boards[i]->avr)) {
			return;
		}
		if (park->limit < horizon + WORLD_SKIP_MARGIN) {
			horizon = park->limit > WORLD_SKIP_MARGIN ? park->limit - WORLD_SKIP_MARGIN : 0;
		}
	}
	if (horizon <= w->now + WORLD_QUANTUM) {
		return;
	}
	end = horizon == target ? target :
	      w->now + (horizon - w->now) / WORLD_QUANTUM * WORLD_QUANTUM;
	for (int i = 0; i < w->nboards; i++) {
		park_stays(&w->park[i], w->boards[i]->avr, end);
	}
	w->now = end;
}

int world_run(world_t *w, uint64_t target, uint32_t bytes)
{
	uint32_t from = w->bus.bytes;
	int parked = 0;

	if (w->nboards == 1) {
		return world_run_one(w, target, bytes);
	}
	while (w->now < target && !world_bytes_came(w, from, bytes)) {
		uint64_t end;

		if (parked == w->nboards) {
			world_skip(w, target);
			if (w->now >= target) {
				break;
			}
		}
		end = w->now + WORLD_QUANTUM;
		if (end > target) {
			end = target;
		}
		parked = 0;
		for (int i = 0; i < w->nboards; i++) {
			avr_t *avr = w->boards[i]->avr;
			park_t *park = &w->park[i];
			int state;

			if (park->parked && park_stays(park, avr, end)) {
				parked++;
				continue;
			}
			state = park_run(park, avr, end, !w->no_park && !profile_boards);
			if (world_state_dead(state)) {
				w->dead = i;
				w->dead_state = state;
				world_unpark(w);
				return 1;
			}
			parked += park->parked;
		}
		w->now = end;
	}
	world_unpark(w);
	return 0;
}

uint32_t world_activity(const world_t *w)
{
	uint32_t a = w->bus.activity;

	for (int i = 0; i < w->nboards; i++) {
		a += sim_board_activity(w->boards[i]);
	}
	return a;
}
