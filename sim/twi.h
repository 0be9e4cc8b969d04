/*
 * twi.h: the simulator's own model of the AVR TWI, replacing simavr 1.6's
 * (TWINT not cleared by writing 1, wrong address-phase status codes, bit
 * rate ignored: see SIMAVR-NOTES.md). It takes over TWBR/TWSR/TWAR/TWDR/TWCR
 * after avr_init and drives a twi_bus_t.
 *
 * Master mode follows the datasheet (status codes 08..58, 38, F8; TWINT,
 * TWEA, TWSTA, TWSTO, TWWC, TWEN, TWIE). Timing: SCL period
 * P = 16 + 2*TWBR*4^TWPS cycles; START and STOP take P, a byte with its
 * acknowledge 9P; TWINT rises at the end.
 *
 * Slave mode (a later issue) hooks in at two points: a twi_dev_t embedded
 * here and attached to the bus (its start() compares TWAR, sets TWSR
 * 60/A8/..., raises TWINT and holds the bus: clock stretching), and the
 * "TWINT cleared while addressed" branch of twi_action().
 */
#ifndef SIM_TWI_H
#define SIM_TWI_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_io.h"
#include "sim_interrupts.h"

#include "mcu.h"
#include "twi_bus.h"

typedef enum twi_op_t {
	TWI_OP_NONE = 0,
	TWI_OP_START,		/* START or repeated START */
	TWI_OP_STOP,
	TWI_OP_STOP_START,	/* TWSTO and TWSTA together */
	TWI_OP_SLA,		/* address byte + ack */
	TWI_OP_TX,		/* data byte out + ack */
	TWI_OP_RX,		/* data byte in + master's ack */
} twi_op_t;

typedef struct twi_t {
	avr_io_t io;			/* first: reset hook */
	avr_t *avr;
	const mcu_twi_regs_t *regs;
	twi_bus_t *bus;
	avr_int_vector_t vect_twi;

	uint8_t status;			/* TWSR bits 7..3 */
	int owner;			/* this master holds the bus */
	twi_op_t op;			/* operation in progress (TWINT low) */
	int op_ack;			/* RX: TWEA when the byte started */
} twi_t;

/* Take over the TWI described by REGS on AVR (after avr_init). */
void twi_init(twi_t *t, avr_t *avr, const mcu_twi_regs_t *regs, twi_bus_t *bus);

/* One SCL period in cycles with the current TWBR and TWPS. */
avr_cycle_count_t twi_scl_period(const twi_t *t);

#endif
