/*
 * twi.h: the simulator's own model of the AVR TWI, replacing simavr 1.6's
 * (TWINT not cleared by writing 1, wrong address-phase status codes, bit
 * rate ignored: see docs/simulator.md, "What simavr 1.6 gets wrong"). It takes
 * over TWBR/TWSR/TWAR/TWDR/TWCR after avr_init and drives a twi_bus_t.
 *
 * Master mode follows the datasheet (status codes 08..58, 38, F8; TWINT,
 * TWEA, TWSTA, TWSTO, TWWC, TWEN, TWIE). It puts every bit on the bus's
 * lines at the SCL period P = 16 + 2*TWBR*4^TWPS cycles (sim_twi.c,
 * "master mode"): START and STOP take P, a byte with its acknowledge 9P;
 * TWINT rises at the end. It samples SDA with SCL high and waits for SCL to
 * rise when a device holds it (clock synchronisation).
 *
 * Slave mode: every TWI is also a device on the bus (sim_twi_t.dev) behind
 * the shared bit-level front (i2c_phy.c). With TWEN and TWEA set it
 * acknowledges its TWAR address (general call not modelled) and gives the
 * datasheet's slave codes 60/80/88/A0 (receiver), A8/B8/C0/C8
 * (transmitter) and 00 (a START or STOP inside a byte). Its TWINT rises at
 * the falling edge of SCL that ends the acknowledge bit (or at the STOP /
 * repeated START); while it is set the slave holds SCL low and the
 * master's next operation waits until the firmware clears TWINT, then
 * takes its normal time from that release (clock stretching).
 *
 * Lines (twi_bus.h): with TWEN off the board's SCL/SDA port pins drive the
 * bus's wired-AND lines (sim_twi_wire_pins). A START waits for a free bus
 * (SDA and SCL high); an operation waits while another driver holds SCL.
 */
#ifndef SIM_TWI_H
#define SIM_TWI_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_io.h"
#include "sim_interrupts.h"

#include "harness/isr_watch.h"
#include "periph/sim_mcu.h"
#include "periph/twi_bus.h"

typedef enum sim_twi_op_t {
	TWI_OP_NONE = 0,
	TWI_OP_START,		/* START or repeated START */
	TWI_OP_STOP,
	TWI_OP_STOP_START,	/* TWSTO and TWSTA together */
	TWI_OP_SLA,		/* address byte + ack */
	TWI_OP_TX,		/* data byte out + ack */
	TWI_OP_RX,		/* data byte in + master's ack */
} sim_twi_op_t;

typedef struct sim_twi_t {
	avr_io_t io;			/* first: reset hook */
	avr_t *avr;
	const sim_mcu_twi_t *regs;
	twi_bus_t *bus;
	avr_int_vector_t vect_twi;
	isr_watch_t isr;		/* how long the TWI interrupt runs */

	uint8_t status;			/* TWSR bits 7..3 */
	int owner;			/* this master holds the bus */
	sim_twi_op_t op;		/* operation in progress (TWINT low) */
	int op_ack;			/* RX: TWEA when the byte started */
	twi_bus_master_t master;	/* the bus resumes a waiting master here */
	twi_drv_t drv;			/* the master's pull on the lines */
	/* the operation's bits (sim_twi.c, "master mode") */
	avr_cycle_count_t half;		/* half an SCL period, cycles */
	avr_cycle_count_t step_at;	/* the exact cycle of the next step */
	avr_cycle_count_t bit_at;	/* the cycle the bit's SCL low began */
	avr_cycle_count_t fall_at;	/* START: the cycle SCL falls */
	uint8_t step;			/* what the timer does next */
	uint8_t waiting;		/* twi_wait_t the master waits for */
	uint8_t bit;			/* 0..8 in a byte (8: the acknowledge) */
	uint8_t byte;			/* the byte going out or coming in */
	uint8_t line_ack;		/* SLA/TX: the acknowledge on SDA */
	uint8_t line_byte;		/* SLA/TX: the byte as SDA carried it */
	uint8_t lost;			/* it lost arbitration in this byte */
	uint8_t fault, fault_bit;	/* twi_fault_kind_t armed for this byte, its bit */

	/* slave mode */
	twi_dev_t dev;			/* this TWI as a device on the bus */
	int addressed;			/* 0, or TWI_SLAVE_RX / TWI_SLAVE_TX */
	int sl_got_addr;		/* the address acknowledged, no byte yet */
	int sl_ea;			/* TWEA when TWINT was last cleared */
	uint8_t sl_tx;			/* TWDR when TWINT was last cleared (ST) */
	uint8_t sl_rx;			/* the byte received (SR) */
	int sl_pending;			/* a TWINT rise is scheduled */
	uint8_t sl_status;		/* ... with this status */
	int sl_has_data;		/* ... and this received byte */
	uint8_t sl_data;
	avr_cycle_count_t sl_at;	/* ... at this cycle */
	uint8_t sl_addr;		/* TWAR address it answered (trace), 00: the general call */
	int sl_gcall;			/* addressed by the general call (TWGCE) */

	/* SCL/SDA as port pins while TWEN is off (sim_twi_wire_pins) */
	twi_drv_t pins;
	int pins_wired;
	uint8_t pin_scl, pin_sda;	/* bit numbers */
	uint8_t pin_ddr, pin_port;	/* shadows of the port's DDR/PORT */
} sim_twi_t;

#define TWI_SLAVE_RX 1
#define TWI_SLAVE_TX 2

/* Take over the TWI described by REGS on AVR (after avr_init). */
void sim_twi_init(sim_twi_t *t, avr_t *avr, const sim_mcu_twi_t *regs, twi_bus_t *bus);

/* The TWI's lines are pins SCL and SDA of port PORT ('C'): while TWEN is
 * off the firmware drives them as port pins (DDR 1 and PORT 0 pulls the
 * line low; anything else releases it to the external pull-ups), and the
 * bus's wired-AND lines hear it. 0, or -1 when the port is not found. */
int sim_twi_wire_pins(sim_twi_t *t, char port, int scl, int sda);

/* One SCL period in cycles with the current TWBR and TWPS. */
avr_cycle_count_t sim_twi_scl_period(const sim_twi_t *t);

#endif
