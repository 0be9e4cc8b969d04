/*
 * board_m32d.c: the OR-AVR-M32-D's wiring, from boards/m32d/board.h.
 */
#include "boards/m32d/board.h"
#include "board_wiring.h"

#define BW_ENTRY(port, bit, fn, index) { port, bit, BW_##fn, index },
static const board_pin_t m32d_pins[] = { BOARD_PINS(BW_ENTRY) };

const board_wiring_t board_m32d_wiring = {
	.pins = m32d_pins,
	.npins = sizeof(m32d_pins) / sizeof(m32d_pins[0]),
	.adc_port = BOARD_ADC_PORT,
	.host_usart = BOARD_UART,
	.servo_counters = 0,
	.servo_per_counter = 0,
};
