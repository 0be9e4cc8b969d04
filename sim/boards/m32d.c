/*
 * m32d.c: the board boards/m32d/board.h describes: its names, MCU and wiring.
 */
#include "boards/m32d/board.h"

#define SIM_BOARD sim_board_m32d
#include "boards/board_from_header.h"
