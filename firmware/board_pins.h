/*
 * The board's pin map (BOARD_PINS in boards/<board>/board.h) as a table in
 * flash, so drivers look pins up by function instead of naming them.
 */
#ifndef ORFA_BOARD_PINS_H
#define ORFA_BOARD_PINS_H

#include <stdint.h>

#include "board.h"
#include "firmware/board_fn.h"
#include "firmware/flash.h"
#include "firmware/pins.h"

#define BOARD_PIN_NONE 0xFF

/* The pin with function `fn` and index `index`, or BOARD_PIN_NONE. */
uint8_t board_pin(board_fn_t fn, uint8_t index);

/* Every pin with function `fn`: pins[index] = its pin, in one walk of the
 * map (a board_pin() per index walks it each time). Indices not in the map
 * are left as they were. */
void board_pins_of(board_fn_t fn, uint8_t *pins);

/* The same for `fn` and `index` known when compiling: the pin map as tests
 * of constants, which the compiler folds to the pin's number (no code, no
 * table walked; board_pin() searches 28 rows on the M32-D). A variable
 * argument would inline every test: use board_pin() then. */
static inline __attribute__((always_inline)) uint8_t board_pin_at(board_fn_t fn, uint8_t index)
{
#define BOARD_PIN_IF(port, line, function, idx) \
	if (fn == BF_##function && index == (idx)) { \
		return PIN_ID(port, line); \
	}
	BOARD_PINS(BOARD_PIN_IF)
#undef BOARD_PIN_IF
	return BOARD_PIN_NONE;
}

/* Whether `pin` has function `fn` (any index) in the map, `fn` a constant:
 * folded as board_pin_at() is, to a test of the pin against the few pins
 * with that function (none: false, no code). */
static inline __attribute__((always_inline)) uint8_t board_pin_has(uint8_t pin, board_fn_t fn)
{
#define BOARD_PIN_HAS_IF(port, line, function, idx) \
	if (fn == BF_##function && pin == PIN_ID(port, line)) { \
		return 1; \
	}
	BOARD_PINS(BOARD_PIN_HAS_IF)
#undef BOARD_PIN_HAS_IF
	return 0;
}

#endif
