/*
 * twi_bus.h: an I2C bus. Masters call the bus for each bus event; every
 * device on the bus sees every START/address and STOP (as on a real bus),
 * the addressed one answers data. An address nobody claims is not
 * acknowledged; a read with nobody selected returns FF (pull-ups).
 *
 * A device is a context struct whose first member is a twi_dev_t (simavr's
 * part style). Simple devices (the EEPROM) answer at once. A simulated
 * board's TWI in slave mode is a device too; it may hold SCL low (clock
 * stretching) while its firmware has TWINT set: twi_bus_hold() and
 * twi_bus_release(). A master asks twi_bus_begin() before each operation;
 * while a device holds SCL the operation waits, and the bus resumes the
 * master with the release's cycle. One master per bus (no arbitration).
 */
#ifndef SIM_TWI_BUS_H
#define SIM_TWI_BUS_H

#include <stdint.h>

#include "harness/signals.h"
#include "harness/trace.h"
#include "periph/twi_fault.h"

typedef struct twi_dev_t twi_dev_t;

typedef struct twi_dev_ops_t {
	/* START (or repeated START) then ADDR8 (8-bit address, bit 0 = R/W).
	 * Return 1 to acknowledge (claim the transfer), 0 otherwise. */
	int (*start)(twi_dev_t *dev, uint8_t addr8);
	/* Master wrote BYTE to the selected device: return 1 for ACK. */
	int (*write)(twi_dev_t *dev, uint8_t byte);
	/* Master reads a byte; MASTER_ACKS says how the master answers it. */
	uint8_t (*read)(twi_dev_t *dev, int master_acks);
	/* STOP on the bus (all devices). */
	void (*stop)(twi_dev_t *dev);
	/* Optional (NULL: not told): a START condition completed (all
	 * devices), before any address; a repeated START ends a transfer. */
	void (*bus_start)(twi_dev_t *dev);
	/* Optional (NULL: told the plain START or STOP): a START or STOP in
	 * the middle of a byte of the transfer this device was selected for
	 * (twi_bus_glitch): a TWI's bus error. */
	void (*bus_error)(twi_dev_t *dev);
} twi_dev_ops_t;

/* How a device holds SCL low. */
typedef enum twi_hold_t {
	TWI_HOLD_NONE = 0,
	/* Low after an acknowledge bit: every master operation waits. */
	TWI_HOLD_ALL,
	/* TWINT set by a STOP or repeated START (0xA0): SCL was high then,
	 * so the START/STOP pass, but the next address byte waits. */
	TWI_HOLD_ADDR,
} twi_hold_t;

struct twi_dev_t {
	const twi_dev_ops_t *ops;
	const char *name;
	twi_dev_t *next;
	twi_hold_t hold;	/* set through twi_bus_hold/twi_bus_release only */
};

/* What a master is about to put on the bus (decides which holds stop it). */
typedef enum twi_bus_op_t {
	TWI_BUS_START,		/* START, repeated START */
	TWI_BUS_ADDR,		/* address byte */
	TWI_BUS_DATA,		/* data byte, either direction */
	TWI_BUS_STOP,
} twi_bus_op_t;

/* A master's handle: the bus calls RESUME when its waiting operation may
 * begin, with the cycle it begins at. */
typedef struct twi_bus_master_t {
	void (*resume)(struct twi_bus_master_t *m, uint64_t cycle);
} twi_bus_master_t;

/* A board's port-pin drivers of the lines (its TWI off, the firmware
 * driving SDA/SCL as port pins): set through twi_bus_pins only. */
typedef struct twi_pins_t {
	struct twi_pins_t *next;
	int sda_low, scl_low;
} twi_pins_t;

/* Told when a line's level changes (a board model's pin signals). */
typedef void (*twi_line_fn)(void *param, uint64_t cycle);

#define TWI_BUS_LISTENERS 16

typedef struct twi_bus_t {
	twi_dev_t *devs;
	twi_dev_t *selected;	/* device that acknowledged the address */
	int busy;		/* between START and STOP */
	trace_t *trace;
	uint32_t activity;	/* bumps on every bus event */
	uint64_t cycle;		/* cycle of the event being delivered to devices */

	/* clock stretching */
	twi_bus_master_t *waiter;	/* master whose operation waits */
	twi_bus_op_t waiter_op;
	uint64_t waiter_since;		/* cycle it wanted to begin */
	uint64_t released_all;		/* last release of a TWI_HOLD_ALL */
	uint64_t released_addr;		/* last release of a TWI_HOLD_ADDR */
	uint8_t released_all_by, released_addr_by;	/* their slaves' addresses */

	/* SDA and SCL as wired-AND lines (1 = released, the pull-ups) */
	int sda, scl;
	int scl_ext;		/* SCL without the TWIs' clock stretching (traced) */
	uint32_t stuck;		/* SCL pulses the stuck device still waits for (0: off) */
	int hold_scl;		/* a device holds SCL low */
	twi_pins_t *pins;
	twi_line_fn listener[TWI_BUS_LISTENERS];
	void *listener_param[TWI_BUS_LISTENERS];
	int nlisteners;
	/* the signal "i2c": 1 from the end of a START to the end of its STOP,
	 * the bus's activity in the VCD and to `edges` (NULL: none) */
	signal_t *busy_signal;
	/* a fault armed for the middle of a byte (`i2c arb`, `i2c glitch`) */
	twi_fault_t fault;
} twi_bus_t;

void twi_bus_init(twi_bus_t *bus, trace_t *trace);
void twi_bus_attach(twi_bus_t *bus, twi_dev_t *dev);

/* Bus events, each stamped with the cycle it completes at. */
void twi_bus_start(twi_bus_t *bus, uint64_t cycle);
int twi_bus_address(twi_bus_t *bus, uint64_t cycle, uint8_t addr8);
int twi_bus_write(twi_bus_t *bus, uint64_t cycle, uint8_t byte);
uint8_t twi_bus_read(twi_bus_t *bus, uint64_t cycle, int master_acks);
void twi_bus_stop(twi_bus_t *bus, uint64_t cycle);
/* A START (START 1) or STOP condition at CYCLE in the middle of a byte
 * (twi_fault.h): the selected device gets its bus error, every other one
 * the plain condition; nobody is selected after it. */
void twi_bus_glitch(twi_bus_t *bus, uint64_t cycle, int start);

/* Master M wants to begin OP at cycle NOW. Returns the cycle it begins at
 * (NOW, or later when a device released SCL after NOW), or 0 when a device
 * holds SCL: M->resume() is called on the release. */
uint64_t twi_bus_begin(twi_bus_t *bus, twi_bus_master_t *m, twi_bus_op_t op, uint64_t now);

/* M's waiting operation is abandoned (TWI off, reset). */
void twi_bus_cancel(twi_bus_t *bus, twi_bus_master_t *m);

/* DEV holds SCL low (from the event being delivered on). */
void twi_bus_hold(twi_bus_t *bus, twi_dev_t *dev, twi_hold_t how);

/* DEV (answering at ADDR8, for the trace) lets SCL go at CYCLE. A master
 * that waited on it gets a `twi stretch ADDR8 CYCLES` trace line. */
void twi_bus_release(twi_bus_t *bus, twi_dev_t *dev, uint64_t cycle, uint8_t addr8);

/* --- the lines ------------------------------------------------------------
 *
 * SDA and SCL are wired-AND: a line is high (pull-ups) unless something
 * pulls it low: a board's firmware driving the pin as a port pin while its
 * TWI is off (twi_pins_t), a board's TWI holding SCL after an acknowledge
 * (TWI_HOLD_ALL), the stuck device (SDA) or the SCL-holding device.
 * While SCL is held low by a device or a pin, every master operation waits
 * (the TWI's SCL never rises: TWINT never sets); while SDA is low, a START
 * waits for the bus to be free (the TWI waits for a STOP; the release of
 * SDA with SCL high is one). */

/* Attach a board's pin drivers (both released). */
void twi_bus_attach_pins(twi_bus_t *bus, twi_pins_t *pins);

/* The pins' drivers changed at CYCLE. */
void twi_bus_pins(twi_bus_t *bus, twi_pins_t *pins, int sda_low, int scl_low, uint64_t cycle);

/* Call FN(PARAM, cycle) whenever a line changes level. 0, -1 when full. */
int twi_bus_listen(twi_bus_t *bus, twi_line_fn fn, void *param);

/* The stuck device holds SDA low until it has seen PULSES more SCL pulses
 * (falling edges); 0 lets SDA go at once. */
void twi_bus_stuck(twi_bus_t *bus, uint32_t pulses, uint64_t cycle);

/* The SCL-holding device holds SCL low (ON) or lets it go. */
void twi_bus_hold_scl(twi_bus_t *bus, int on, uint64_t cycle);

/* Recompute the lines at CYCLE (after any driver changed). */
void twi_bus_lines(twi_bus_t *bus, uint64_t cycle);

#endif
