#include "firmware/board_pins.h"

#include "board.h"
#include "firmware/pins.h"

typedef struct {
	uint8_t pin;
	uint8_t fn;
	uint8_t index;
} board_pin_t;

static const ORFA_FLASH board_pin_t board_pins[] = {
#define X(port, line, function, idx) { PIN_ID(port, line), BF_##function, idx },
	BOARD_PINS(X)
#undef X
};

#define BOARD_NPINS ((uint8_t)(sizeof board_pins / sizeof board_pins[0]))

uint8_t board_pin(board_fn_t fn, uint8_t index)
{
	for (uint8_t i = 0; i < BOARD_NPINS; i++) {
		if (board_pins[i].fn == fn && board_pins[i].index == index) {
			return board_pins[i].pin;
		}
	}
	return BOARD_PIN_NONE;
}

void board_pins_of(board_fn_t fn, uint8_t *pins)
{
	for (uint8_t i = 0; i < BOARD_NPINS; i++) {
		if (board_pins[i].fn == fn) {
			pins[board_pins[i].index] = board_pins[i].pin;
		}
	}
}
