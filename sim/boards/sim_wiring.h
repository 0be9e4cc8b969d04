/*
 * sim_wiring.h: a board's fixed wiring as data, read from
 * boards/<board>/board.h by sim/boards/<board>.c.
 */
#ifndef SIM_WIRING_H
#define SIM_WIRING_H

#include <stdint.h>

#include "firmware/board_fn.h"		/* board.h's pin functions, BF_* */

typedef struct sim_pin_t {
	char port;			/* 'A'.. */
	uint8_t bit;
	board_fn_t fn;
	uint8_t index;
} sim_pin_t;

typedef struct sim_wiring_t {
	const sim_pin_t *pins;
	int npins;
	char adc_port;			/* port whose lines are ADC0..7 */
	int host_usart;			/* the PC's serial port: the MCU's USART n */
	int servo_counters;		/* CD4017s (0: servos on plain pins) */
	int servo_per_counter;
} sim_wiring_t;

/* The pin with function FN and INDEX, or NULL. */
const sim_pin_t *sim_wiring_pin(const sim_wiring_t *w, board_fn_t fn, int index);

#endif
