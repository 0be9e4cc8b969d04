/*
 * board.h: the boards the simulator knows: which MCU, which USART is the
 * serial port to the PC, and the wiring read from boards/<board>/board.h
 * (board_wiring.h) for the board model (board_model.h).
 */
#ifndef SIM_BOARD_H
#define SIM_BOARD_H

#include <stdint.h>

typedef struct board_desc_t {
	const char *name;	/* --board value: "m32d" */
	const char *title;	/* "OR-AVR-M32-D" */
	const char *mcu;	/* simavr MCU name */
	const struct board_wiring_t *wiring;
} board_desc_t;

/* The board called NAME, or NULL. */
const board_desc_t *board_find(const char *name);

/* "m32d|m128s", for usage messages. */
const char *board_names(void);

#endif
