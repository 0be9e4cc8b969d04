/*
 * sim_boards.h: the boards the simulator knows: their names, MCU and
 * wiring, each read from boards/<board>/board.h by sim/boards/<board>.c
 * (one file per board, since every board header defines the same macro
 * names), for the board model (board_model.h).
 */
#ifndef SIM_BOARDS_H
#define SIM_BOARDS_H

#include <stdint.h>

#include "boards/sim_wiring.h"

typedef struct sim_board_desc_t {
	const char *name;	/* --board value: BOARD_ID, "m32d" */
	const char *title;	/* BOARD_NAME, "OR-AVR-M32-D" */
	const char *mcu;	/* BOARD_MCU_NAME, simavr's MCU name */
	uint32_t hz;		/* BOARD_CLOCK_HZ */
	sim_wiring_t wiring;
} sim_board_desc_t;

extern const sim_board_desc_t sim_board_m32d;
extern const sim_board_desc_t sim_board_m128s;

/* The board called NAME, or NULL. */
const sim_board_desc_t *sim_board_find(const char *name);

/* The clock of the simulated world: the boards' BOARD_CLOCK_HZ, which must
 * agree, since the world steps every board by one cycle count (world.h); a
 * board that differs stops the simulator here with a message (exit 2). */
uint32_t sim_boards_hz(void);

/* "m32d|m128s", for usage messages. */
const char *sim_board_names(void);

#endif
