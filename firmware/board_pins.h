/*
 * The board's pin map (BOARD_PINS in boards/<board>/board.h) as a table in
 * flash, so drivers look pins up by function instead of naming them.
 */
#ifndef ORFA_BOARD_PINS_H
#define ORFA_BOARD_PINS_H

#include <stdint.h>

#include "firmware/flash.h"

/* The functions a board file may give a pin. */
typedef enum {
	BF_UART_RX, BF_UART_TX,
	BF_TWI_SCL, BF_TWI_SDA,
	BF_SPI_SS, BF_SPI_MOSI, BF_SPI_MISO, BF_SPI_SCK,
	BF_MOTOR_PWM, BF_MOTOR_DIR,
	BF_SERVO, BF_SERVO_CLK, BF_SERVO_RST,
} board_fn_t;

#define BOARD_PIN_NONE 0xFF

/* The pin with function `fn` and index `index`, or BOARD_PIN_NONE. */
uint8_t board_pin(board_fn_t fn, uint8_t index);

/* Whether `pin` has function `fn` (any index) in the map. */
uint8_t board_pin_has(uint8_t pin, board_fn_t fn);

#endif
