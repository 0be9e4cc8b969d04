/*
 * world.c: the lock-step loop over the boards.
 */
#include <string.h>

#include "harness/avr_step.h"
#include "harness/world.h"

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

/* One board alone needs no lock-step: the loop stays as tight as the
 * single-board simulator's always was. */
static int world_run_one(world_t *w, uint64_t target)
{
	avr_t *avr = w->boards[0]->avr;

	int state = avr_step_until(avr, target);

	if (world_state_dead(state)) {
		w->dead = 0;
		w->dead_state = state;
		return 1;
	}
	w->now = avr->cycle;
	return 0;
}

int world_run(world_t *w, uint64_t target)
{
	if (w->nboards == 1) {
		return world_run_one(w, target);
	}
	while (w->now < target) {
		uint64_t end = w->now + WORLD_QUANTUM;

		if (end > target) {
			end = target;
		}
		for (int i = 0; i < w->nboards; i++) {
			avr_t *avr = w->boards[i]->avr;

			int state = avr_step_until(avr, end);

			if (world_state_dead(state)) {
				w->dead = i;
				w->dead_state = state;
				return 1;
			}
		}
		w->now = end;
	}
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
