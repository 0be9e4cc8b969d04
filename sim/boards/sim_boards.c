/*
 * sim_boards.c: the list of boards (each described by its own board.h).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "boards/sim_boards.h"

static const sim_board_desc_t *const sim_board_table[] = {
	&sim_board_m32d,
	&sim_board_m128s,
};

#define SIM_NBOARDS (sizeof(sim_board_table) / sizeof(sim_board_table[0]))

const sim_board_desc_t *sim_board_find(const char *name)
{
	for (unsigned i = 0; i < SIM_NBOARDS; i++) {
		if (strcmp(sim_board_table[i]->name, name) == 0) {
			return sim_board_table[i];
		}
	}
	return NULL;
}

uint32_t sim_boards_hz(void)
{
	const sim_board_desc_t *first = sim_board_table[0];

	for (unsigned i = 1; i < SIM_NBOARDS; i++) {
		if (sim_board_table[i]->hz != first->hz) {
			fprintf(stderr, "orfa-sim: boards %s (%lu Hz) and %s (%lu Hz) differ in"
				" clock: the simulator steps every board by one cycle count\n",
				first->name, (unsigned long)first->hz, sim_board_table[i]->name,
				(unsigned long)sim_board_table[i]->hz);
			exit(2);
		}
	}
	return first->hz;
}

const char *sim_board_names(void)
{
	static char names[64];

	if (!names[0]) {
		for (unsigned i = 0; i < SIM_NBOARDS; i++) {
			if (i) {
				strcat(names, "|");
			}
			strcat(names, sim_board_table[i]->name);
		}
	}
	return names;
}

const sim_pin_t *sim_wiring_pin(const sim_wiring_t *w, board_fn_t fn, int index)
{
	for (int i = 0; i < w->npins; i++) {
		if (w->pins[i].fn == fn && w->pins[i].index == index) {
			return &w->pins[i];
		}
	}
	return NULL;
}
