/*
 * twi_bus.h: an I2C bus as two wired-AND lines, SDA and SCL.
 *
 * Every driver of the lines (a master TWI, each device's bit-level front,
 * a board's port pins while its TWI is off, the stuck-SDA and SCL-holding
 * fault devices) is a twi_drv_t with its own pull-low flags; a line is high
 * (the pull-ups) unless some driver pulls it low. Drivers change through
 * twi_bus_drive() with the cycle of the change; the bus tells every change
 * of a line's level, stamped with that cycle, to the devices (i2c_phy.c),
 * the line signals (VCD, `edges`), the board pin models and a master
 * waiting for the line. A change made while a change is being told (a
 * device answering an SCL edge) is told after it, with its own cycle, so
 * every listener sees the edges in one order.
 *
 * A device is a context struct whose first member is a twi_dev_t (simavr's
 * part style). Its bit-level front (the phy, sim/periph/i2c_phy.c) reads the
 * bits from the lines and calls the device's byte-level ops; a simulated
 * board's TWI in slave mode is a device too, and may hold SCL low (clock
 * stretching) after an acknowledge bit: twi_bus_release() lets it go.
 *
 * The trace lines `twi start|addr|write|read|stop` and the "i2c" busy
 * signal are the master's account of what it put on and read from the
 * lines (twi_bus_note_*), stamped when each operation completes.
 */
#ifndef SIM_TWI_BUS_H
#define SIM_TWI_BUS_H

#include <stdint.h>

#include "harness/signals.h"
#include "harness/trace.h"
#include "periph/twi_fault.h"

typedef struct twi_dev_t twi_dev_t;

typedef struct twi_dev_ops_t {
	/* An address byte ADDR8 (bit 0 = R/W) after a START or repeated START,
	 * at its 8th SCL falling edge. Return 1 to acknowledge (claim the
	 * transfer), 0 otherwise (the device then ignores the bits until the
	 * next START). */
	int (*start)(twi_dev_t *dev, uint8_t addr8);
	/* The master wrote BYTE to this device (8th falling edge): 1 for ACK. */
	int (*write)(twi_dev_t *dev, uint8_t byte);
	/* The master reads a byte from this device: the byte whose first bit
	 * goes on SDA now (after the acknowledge bit before it). */
	uint8_t (*read)(twi_dev_t *dev);
	/* STOP on the bus (all devices). */
	void (*stop)(twi_dev_t *dev);
	/* Optional (NULL: not told): a START condition (all devices), before
	 * any address; a repeated START ends a transfer. */
	void (*bus_start)(twi_dev_t *dev);
	/* Optional: the acknowledge bit of a byte this device took part in
	 * ended (its SCL falling edge); ACK as the line had it. Return 1 to
	 * hold SCL low from now until twi_bus_release(). */
	int (*ack_end)(twi_dev_t *dev, int ack);
	/* Optional: a START or STOP at an illegal position (in a byte or its
	 * acknowledge bit, after its first bit; the datasheet's bus error),
	 * told instead of bus_start/stop; the phy then waits for the next
	 * START. NULL: told as the START or STOP it is. */
	void (*bus_error)(twi_dev_t *dev);
} twi_dev_ops_t;

/* One driver of the lines: 1 pulls the line low. Set through
 * twi_bus_drive() only. EXT: a fault device or port pins, whose AND is
 * traced as `twi line` (the TWIs and parts are not). */
typedef struct twi_drv_t {
	uint8_t sda_low, scl_low;
	uint8_t ext;
} twi_drv_t;

/* How a device holds SCL low. */
typedef enum twi_hold_t {
	TWI_HOLD_NONE = 0,
	/* Low from now (after an acknowledge bit). */
	TWI_HOLD_ALL,
	/* Low from SCL's next falling edge (TWINT set by a STOP or repeated
	 * START, 0xA0: SCL was high then, so the START passes but the address
	 * byte after it waits). */
	TWI_HOLD_ADDR,
} twi_hold_t;

/* The phy's state (i2c_phy.c). */
typedef enum twi_phy_state_t {
	TWI_PHY_IDLE = 0,	/* waits for a START: sees START/STOP only */
	TWI_PHY_ADDR,		/* shifts in an address byte */
	TWI_PHY_RX,		/* addressed, the master writes */
	TWI_PHY_TX,		/* addressed, the master reads */
} twi_phy_state_t;

struct twi_dev_t {
	const twi_dev_ops_t *ops;
	const char *name;
	twi_dev_t *next;
	twi_drv_t drv;		/* its pull on the lines (the phy's) */
	twi_hold_t hold;	/* set through the phy only */
	/* the phy (i2c_phy.c) */
	uint8_t phy;		/* twi_phy_state_t */
	uint8_t nbits;		/* SCL rising edges since the byte began */
	uint8_t shift;		/* the byte coming in or going out */
	uint8_t ack;		/* the acknowledge this byte gets */
	uint8_t waiting;	/* held after an acknowledge: the next byte waits */
	uint8_t load;		/* its next byte is taken when the master begins it */
};

/* A master's handle: the bus calls RESUME when what it waits for
 * (twi_bus_wait) came, with the cycle it came at. */
typedef struct twi_bus_master_t {
	void (*resume)(struct twi_bus_master_t *m, uint64_t cycle);
	/* A START or STOP the lines carried at CYCLE while it clocked a byte
	 * (twi_bus_t.in_byte): its bus error. */
	void (*condition)(struct twi_bus_master_t *m, uint64_t cycle);
} twi_bus_master_t;

/* What a master waits for. */
typedef enum twi_wait_t {
	TWI_WAIT_NONE = 0,
	TWI_WAIT_SCL_HIGH,	/* it let SCL go: the line's rise (clock synchronisation) */
	TWI_WAIT_SCL_FREE,	/* nobody but itself holds SCL (a slave's stretch) */
	TWI_WAIT_BUS_FREE,	/* SDA and SCL high (a START) */
} twi_wait_t;

/* Told when a line's level changes (a board model's pin signals): SCL
 * (SCL_LINE 1) or SDA, at CYCLE. */
typedef void (*twi_line_fn)(void *param, int scl_line, uint64_t cycle);

#define TWI_BUS_LISTENERS 16

typedef struct twi_bus_t {
	twi_dev_t *devs;
	trace_t *trace;
	uint32_t activity;	/* bumps on every bus event */
	/* the bytes the masters have clocked (their addr, write and read
	 * notes; `wait i2c` counts them), modulo 2^32. In the padding after
	 * activity: as a 64-bit count at the end it grew the struct, moving
	 * all that follows it in world_t, and make bench's simulator speed
	 * measured 1-2 % lower (layout); here the speed is as before. */
	uint32_t bytes;
	uint64_t cycle;		/* cycle of the edge being told (the devices' time) */

	/* the lines: how many drivers pull each low, the levels told */
	int sda_lows, scl_lows, ext_sda_lows, ext_scl_lows;
	int sda, scl;		/* 1 = released, the pull-ups */
	int sda_ext, scl_ext;	/* the AND of the ext drivers alone (traced) */
	int telling;		/* edges are being told (twi_bus_lines) */
	/* A board's TWI master owns the bus (from its START to its STOP) and
	 * clocks a byte from cycle byte_begin to byte_end (twi_bus_byte). */
	int clocked;
	uint64_t byte_end;
	/* the master lets go in the middle of a byte (its reset, TWEN off):
	 * what its release does to SDA is a bus error to the devices */
	int abort;
	int nactive;		/* devices whose phy is not idle */

	/* the master waiting (one master per bus: no arbitration yet) */
	twi_bus_master_t *waiter;
	twi_drv_t *waiter_drv;
	twi_wait_t waiting;
	uint64_t waiter_since;	/* cycle it began to wait */
	uint64_t scl_free_at;	/* last cycle a device let SCL go */
	uint8_t scl_free_by;	/* ... its address (trace) */

	/* the fault devices */
	twi_drv_t stuck_drv, hold_drv;
	uint32_t stuck;		/* SCL pulses the stuck device still waits for (0: off) */
	int hold_scl;		/* the SCL-holding device holds SCL low */
	/* a fault armed for the middle of a byte (`i2c arb`, `i2c glitch`),
	 * and the rival's pull on SDA (twi_fault.h) */
	twi_fault_t fault;
	twi_drv_t rival_drv;
	/* the master clocking an address or data byte (NULL: none), told of
	 * a START or STOP the lines carry meanwhile */
	twi_bus_master_t *in_byte;

	twi_line_fn listener[TWI_BUS_LISTENERS];
	void *listener_param[TWI_BUS_LISTENERS];
	int nlisteners;
	/* the signal "i2c": 1 from the end of a START to the end of its STOP,
	 * the bus's activity in the VCD and to `edges` (NULL: none) */
	signal_t *busy_signal;
	/* the lines as signals "sda" and "scl" (NULL: none) */
	signal_t *sda_signal, *scl_signal;
} twi_bus_t;

void twi_bus_init(twi_bus_t *bus, trace_t *trace);
void twi_bus_attach(twi_bus_t *bus, twi_dev_t *dev);

/* D pulls SDA / SCL low (1) or lets it go (0) from CYCLE. */
void twi_bus_drive(twi_bus_t *bus, twi_drv_t *d, int sda_low, int scl_low, uint64_t cycle);

/* Attach a driver (both lines released) that is not a device's: a
 * master's, a board's pins. */
void twi_bus_attach_drv(twi_bus_t *bus, twi_drv_t *d, int ext);

/* SCL is held low by a driver other than D. */
static inline int twi_bus_scl_held(const twi_bus_t *bus, const twi_drv_t *d)
{
	return bus->scl_lows > d->scl_low;
}

/* Master M (driving with D) waits from cycle NOW for WHAT; M->resume()
 * is called when it comes. */
void twi_bus_wait(twi_bus_t *bus, twi_bus_master_t *m, twi_drv_t *d, twi_wait_t what,
		  uint64_t now);

/* M's wait is abandoned (TWI off, reset). */
void twi_bus_cancel(twi_bus_t *bus, twi_bus_master_t *m);

/* The TWI master begins clocking a byte at cycle BEGIN, which ends with
 * its acknowledge at END unless SCL is stretched: a device whose byte to
 * send waits for this (i2c_phy.c) takes it now. */
void twi_bus_byte(twi_bus_t *bus, uint64_t begin, uint64_t end);

/* The master's account of its operations: trace lines and the busy signal,
 * at the CYCLE each completes; they also count the bytes (bus->bytes, and
 * for the fault armed, twi_fault.h). */
void twi_bus_note_start(twi_bus_t *bus, uint64_t cycle);
void twi_bus_note_addr(twi_bus_t *bus, uint64_t cycle, uint8_t addr8, int ack);
void twi_bus_note_write(twi_bus_t *bus, uint64_t cycle, uint8_t byte, int ack);
void twi_bus_note_read(twi_bus_t *bus, uint64_t cycle, uint8_t byte, int master_acks);
void twi_bus_note_stop(twi_bus_t *bus, uint64_t cycle);

/* A START (START 1) or STOP condition at CYCLE in the middle of the byte
 * the master clocks (`i2c glitch`, told to the devices without moving the
 * lines): a bus error for a device taking part in it (i2c_phy.c); the
 * fault is spent. */
void twi_bus_glitch(twi_bus_t *bus, uint64_t cycle, int start);

/* DEV holds SCL low: now (TWI_HOLD_ALL) or from SCL's next falling edge. */
void twi_bus_hold(twi_bus_t *bus, twi_dev_t *dev, twi_hold_t how);

/* DEV (answering at ADDR8, for the trace) lets SCL go at CYCLE; a byte it
 * sends begins then. A master that waited on it gets a `twi stretch
 * ADDR8 CYCLES` trace line. */
void twi_bus_release(twi_bus_t *bus, twi_dev_t *dev, uint64_t cycle, uint8_t addr8);

/* DEV forgets its transfer and lets both lines go at CYCLE (its TWI off). */
void twi_bus_forget(twi_bus_t *bus, twi_dev_t *dev, uint64_t cycle);

/* Call FN(PARAM, scl_line, cycle) whenever a line changes level. 0, -1
 * when full. */
int twi_bus_listen(twi_bus_t *bus, twi_line_fn fn, void *param);

/* The stuck device holds SDA low until it has seen PULSES more SCL pulses
 * (falling edges); 0 lets SDA go at once. */
void twi_bus_stuck(twi_bus_t *bus, uint32_t pulses, uint64_t cycle);

/* The SCL-holding device holds SCL low (ON) or lets it go. */
void twi_bus_hold_scl(twi_bus_t *bus, int on, uint64_t cycle);

#endif
