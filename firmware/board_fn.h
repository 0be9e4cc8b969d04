/*
 * The functions a board file may give a pin (BOARD_PINS in
 * boards/<board>/board.h), as one list that the firmware's pin table
 * (board_pins.h), the simulator's wiring (sim/boards/sim_wiring.h) and the
 * board map (tools/mapgen.c) all take theirs from. Data only: no avr-libc,
 * so the host-compiled programs include it too.
 */
#ifndef ORFA_BOARD_FN_H
#define ORFA_BOARD_FN_H

#define BOARD_FN_LIST(X) \
	X(UART_RX) X(UART_TX) \
	X(TWI_SCL) X(TWI_SDA) \
	X(SPI_SS) X(SPI_MOSI) X(SPI_MISO) X(SPI_SCK) \
	X(MOTOR_PWM) X(MOTOR_DIR) \
	X(SERVO) X(SERVO_CLK) X(SERVO_RST)

/* BF_UART_RX, ...: a function as a number, in the list's order. */
typedef enum {
#define BOARD_FN_ENUM(name) BF_##name,
	BOARD_FN_LIST(BOARD_FN_ENUM)
#undef BOARD_FN_ENUM
} board_fn_t;

#endif
