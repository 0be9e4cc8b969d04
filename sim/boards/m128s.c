/*
 * m128s.c: the board boards/m128s/board.h describes: its names, MCU and wiring.
 */
#include "boards/m128s/board.h"

#define SIM_BOARD sim_board_m128s
#include "boards/board_from_header.h"
