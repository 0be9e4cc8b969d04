/*
 * board_from_header.h: the descriptor of the board whose boards/<board>/board.h
 * was included just before, named SIM_BOARD. Included once by each
 * sim/boards/<board>.c: every board header defines the same macro names, so
 * each board needs a file of its own, and this is what they share.
 */
#include "boards/sim_boards.h"

#ifndef SIM_BOARD
#error "define SIM_BOARD, the descriptor's name, before including this file"
#endif

#ifndef BOARD_SERVO_COUNTERS		/* servos on plain pins */
#define BOARD_SERVO_COUNTERS 0
#define BOARD_SERVO_PER_COUNTER 0
#endif

#define SIM_PIN_ENTRY(port, bit, fn, index) { port, bit, BF_##fn, index },
static const sim_pin_t sim_board_pins[] = { BOARD_PINS(SIM_PIN_ENTRY) };

const sim_board_desc_t SIM_BOARD = {
	.name = BOARD_ID,
	.title = BOARD_NAME,
	.mcu = BOARD_MCU_NAME,
	.hz = BOARD_CLOCK_HZ,
	.wiring = {
		.pins = sim_board_pins,
		.npins = sizeof(sim_board_pins) / sizeof(sim_board_pins[0]),
		.adc_port = BOARD_ADC_PORT,
		.host_usart = BOARD_UART,
		.servo_counters = BOARD_SERVO_COUNTERS,
		.servo_per_counter = BOARD_SERVO_PER_COUNTER,
	},
};
