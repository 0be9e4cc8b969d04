/*
 * board.c: board table.
 */
#include <string.h>

#include "board.h"
#include "board_wiring.h"

static const board_desc_t board_table[] = {
	{ .name = "m32d", .title = "OR-AVR-M32-D", .mcu = "atmega32",
	  .wiring = &board_m32d_wiring },
	{ .name = "m128s", .title = "OR-AVR-M128-S", .mcu = "atmega128",
	  .wiring = &board_m128s_wiring },
};

const board_desc_t *board_find(const char *name)
{
	for (unsigned i = 0; i < sizeof(board_table) / sizeof(board_table[0]); i++) {
		if (strcmp(board_table[i].name, name) == 0) {
			return &board_table[i];
		}
	}
	return NULL;
}

const char *board_names(void)
{
	return "m32d|m128s";
}

const board_pin_t *board_wiring_pin(const board_wiring_t *w, board_fn_t fn, int index)
{
	for (int i = 0; i < w->npins; i++) {
		if (w->pins[i].fn == fn && w->pins[i].index == index) {
			return &w->pins[i];
		}
	}
	return NULL;
}
