/*
 * twi_bus.h: an I2C bus. Masters call the bus for each bus event; every
 * device on the bus sees every START/address and STOP (as on a real bus),
 * the addressed one answers data. An address nobody claims is not
 * acknowledged; a read with nobody selected returns FF (pull-ups).
 *
 * A device is a context struct whose first member is a twi_dev_t (simavr's
 * part style). Devices planned beyond the EEPROM plug in here unchanged:
 * another simulated board's TWI in slave mode becomes a device whose
 * callbacks drive its TWSR/TWINT, and a second master adds arbitration at
 * twi_bus_start (status 0x38) without changes to the devices.
 */
#ifndef SIM_TWI_BUS_H
#define SIM_TWI_BUS_H

#include <stdint.h>

#include "trace.h"

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
} twi_dev_ops_t;

struct twi_dev_t {
	const twi_dev_ops_t *ops;
	const char *name;
	twi_dev_t *next;
};

typedef struct twi_bus_t {
	twi_dev_t *devs;
	twi_dev_t *selected;	/* device that acknowledged the address */
	int busy;		/* between START and STOP */
	trace_t *trace;
	uint32_t activity;	/* bumps on every bus event */
	uint64_t now;		/* cycle of the event being delivered, for
				 * devices that keep time (SRF08 ranging) */
} twi_bus_t;

void twi_bus_init(twi_bus_t *bus, trace_t *trace);
void twi_bus_attach(twi_bus_t *bus, twi_dev_t *dev);

/* Bus events, each stamped with the cycle it completes at. */
void twi_bus_start(twi_bus_t *bus, uint64_t cycle);
int twi_bus_address(twi_bus_t *bus, uint64_t cycle, uint8_t addr8);
int twi_bus_write(twi_bus_t *bus, uint64_t cycle, uint8_t byte);
uint8_t twi_bus_read(twi_bus_t *bus, uint64_t cycle, int master_acks);
void twi_bus_stop(twi_bus_t *bus, uint64_t cycle);

#endif
