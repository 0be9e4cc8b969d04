/*
 * board_wiring.h: a board's fixed wiring as data, read from
 * boards/<board>/board.h by sim/board_<board>.c (one file per board, since
 * every board header defines the same macro names).
 */
#ifndef SIM_BOARD_WIRING_H
#define SIM_BOARD_WIRING_H

#include <stdint.h>

/* The function names of board.h's BOARD_PINS(X), prefixed. */
typedef enum board_fn_t {
	BW_UART_RX, BW_UART_TX, BW_TWI_SCL, BW_TWI_SDA,
	BW_SPI_SS, BW_SPI_MOSI, BW_SPI_MISO, BW_SPI_SCK,
	BW_MOTOR_PWM, BW_MOTOR_DIR, BW_SERVO, BW_SERVO_CLK, BW_SERVO_RST,
} board_fn_t;

typedef struct board_pin_t {
	char port;			/* 'A'.. */
	uint8_t bit;
	board_fn_t fn;
	uint8_t index;
} board_pin_t;

typedef struct board_wiring_t {
	const board_pin_t *pins;
	int npins;
	char adc_port;			/* port whose lines are ADC0..7 */
	int host_usart;			/* the PC's serial port: the MCU's USART n */
	int servo_counters;		/* CD4017s (0: servos on plain pins) */
	int servo_per_counter;
} board_wiring_t;

extern const board_wiring_t board_m32d_wiring;
extern const board_wiring_t board_m128s_wiring;

/* The pin with function FN and INDEX, or NULL. */
const board_pin_t *board_wiring_pin(const board_wiring_t *w, board_fn_t fn, int index);

#endif
