/*
 * world.c: the lock-step loop over the boards.
 */
#include <string.h>

#include "world.h"

void world_init(world_t *w)
{
	memset(w, 0, sizeof(*w));
	w->dead = -1;
	twi_bus_init(&w->bus, &w->trace);
}

void world_add_eeprom(world_t *w, uint8_t addr8, int wp)
{
	eeprom24_t *e = &w->eeprom[w->neeprom++];

	eeprom24_init(e, addr8);
	e->write_protect = (uint8_t)!!wp;
	twi_bus_attach(&w->bus, &e->dev);
}

void world_add_srf08(world_t *w, uint8_t addr8)
{
	srf08_t *s = &w->srf08[w->nsrf08++];

	srf08_init(s, addr8, SIM_FREQUENCY, &w->bus);
	twi_bus_attach(&w->bus, &s->dev);
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

	while (avr->cycle < target) {
		int state = avr_run(avr);

		if (world_state_dead(state)) {
			w->dead = 0;
			w->dead_state = state;
			return 1;
		}
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

			while (avr->cycle < end) {
				int state = avr_run(avr);

				if (world_state_dead(state)) {
					w->dead = i;
					w->dead_state = state;
					return 1;
				}
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
