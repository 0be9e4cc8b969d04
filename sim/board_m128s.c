/*
 * board_m128s.c: the OR-AVR-M128-S's wiring, from boards/m128s/board.h.
 */
#include "boards/m128s/board.h"
#include "board_wiring.h"

#define BW_ENTRY(port, bit, fn, index) { port, bit, BW_##fn, index },
static const board_pin_t m128s_pins[] = { BOARD_PINS(BW_ENTRY) };

const board_wiring_t board_m128s_wiring = {
	.pins = m128s_pins,
	.npins = sizeof(m128s_pins) / sizeof(m128s_pins[0]),
	.adc_port = BOARD_ADC_PORT,
	.host_usart = BOARD_UART,
	.servo_counters = BOARD_SERVO_COUNTERS,
	.servo_per_counter = BOARD_SERVO_PER_COUNTER,
};

