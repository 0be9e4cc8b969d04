/*
 * The board's pin map (BOARD_PINS in boards/<board>/board.h) as a table in
 * flash, so drivers look pins up by function instead of naming them.
 */
#ifndef ORFA_BOARD_PINS_H
#define ORFA_BOARD_PINS_H

#include <stdint.h>

#include "firmware/board_fn.h"
#include "firmware/flash.h"

#define BOARD_PIN_NONE 0xFF

/* The pin with function `fn` and index `index`, or BOARD_PIN_NONE. */
uint8_t board_pin(board_fn_t fn, uint8_t index);

/* Whether `pin` has function `fn` (any index) in the map. */
uint8_t board_pin_has(uint8_t pin, board_fn_t fn);

#endif
