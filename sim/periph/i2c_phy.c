/*
 * i2c_phy.c: the bit-level front of an I2C device (i2c_phy.h).
 */
#include "periph/i2c_phy.h"

void i2c_phy_state(twi_bus_t *bus, twi_dev_t *d, twi_phy_state_t state)
{
	if ((d->phy != TWI_PHY_IDLE) != (state != TWI_PHY_IDLE)) {
		bus->nactive += state != TWI_PHY_IDLE ? 1 : -1;
	}
	d->phy = (uint8_t)state;
}

static void phy_sda(twi_bus_t *bus, twi_dev_t *d, int low, uint64_t cycle)
{
	twi_bus_drive(bus, &d->drv, low, d->drv.scl_low, cycle);
}

/*
 * A device's byte ops run with the bus's cycle set to the device's time:
 * while a board's TWI clocks the bus, the cycle its byte's acknowledge
 * bit ends (twi_bus_byte: the cycle the trace stamps the byte with, as in
 * the byte-level model before the lines), so what a part measures and when
 * it is busy is in the trace's terms; else the edge's own cycle.
 */
#define PHY_OP(bus, call) ({						\
	uint64_t edge_ = (bus)->cycle;					\
	if ((bus)->clocked) {						\
		(bus)->cycle = (bus)->byte_end;				\
	}								\
	__typeof__(call) r_ = (call);					\
	(bus)->cycle = edge_;						\
	r_;								\
})

/* The next byte to send: its first bit (bit 7) goes on SDA now. */
static void phy_send(twi_bus_t *bus, twi_dev_t *d, uint64_t cycle)
{
	d->load = 0;
	d->shift = PHY_OP(bus, d->ops->read(d));
	phy_sda(bus, d, !(d->shift & 0x80), cycle);
}

void i2c_phy_load(twi_bus_t *bus, twi_dev_t *d, uint64_t cycle)
{
	phy_send(bus, d, cycle);
}

void i2c_phy_condition(twi_bus_t *bus, twi_dev_t *d, int start)
{
	/* A START or STOP comes in the high half of a byte's first bit (the
	 * SCL pulse after an acknowledge); later in a byte it is a bus error. */
	int illegal = d->phy != TWI_PHY_IDLE && (d->nbits > 1 || bus->abort);

	/* SDA moved, so this device does not pull it (a glitch moves no line,
	 * twi_bus_glitch: then it lets SDA go, its front starting over); a
	 * byte under way ends */
	if (d->drv.sda_low) {
		phy_sda(bus, d, 0, bus->cycle);
	}
	d->nbits = 0;
	d->shift = 0;
	d->waiting = 0;
	d->load = 0;
	if (illegal && d->ops->bus_error) {
		d->ops->bus_error(d);
		i2c_phy_state(bus, d, TWI_PHY_IDLE);
	} else if (start) {
		if (d->ops->bus_start) {
			d->ops->bus_start(d);
		}
		i2c_phy_state(bus, d, TWI_PHY_ADDR);
	} else {
		d->ops->stop(d);
		i2c_phy_state(bus, d, TWI_PHY_IDLE);
	}
}

/* The 8th falling edge: the byte is in (or out); the acknowledge bit's
 * low half begins. */
static void phy_byte_end(twi_bus_t *bus, twi_dev_t *d)
{
	switch (d->phy) {
	case TWI_PHY_ADDR:
		d->ack = (uint8_t)!!PHY_OP(bus, d->ops->start(d, d->shift));
		if (!d->ack) {
			i2c_phy_state(bus, d, TWI_PHY_IDLE);	/* deaf until the next START */
			return;
		}
		break;
	case TWI_PHY_RX:
		d->ack = (uint8_t)!!PHY_OP(bus, d->ops->write(d, d->shift));
		break;
	default:
		phy_sda(bus, d, 0, bus->cycle);		/* the master acknowledges */
		return;
	}
	if (d->ack) {
		phy_sda(bus, d, 1, bus->cycle);
	}
}

/* The 9th falling edge: the acknowledge bit ended. */
static void phy_ack_end(twi_bus_t *bus, twi_dev_t *d)
{
	twi_phy_state_t next = (twi_phy_state_t)d->phy;
	int ack = d->ack;

	if (d->phy == TWI_PHY_ADDR) {
		next = d->shift & 1 ? TWI_PHY_TX : TWI_PHY_RX;
	} else if (!ack) {
		next = TWI_PHY_IDLE;	/* NACKed: not addressed until the next START */
	}
	if (d->phy != TWI_PHY_TX) {
		phy_sda(bus, d, 0, bus->cycle);
	}
	d->nbits = 0;
	d->shift = 0;
	i2c_phy_state(bus, d, next);
	if (d->ops->ack_end && d->ops->ack_end(d, ack)) {
		d->hold = TWI_HOLD_ALL;
		d->waiting = 1;
		twi_bus_drive(bus, &d->drv, d->drv.sda_low, 1, bus->cycle);
		return;
	}
	if (next == TWI_PHY_TX) {
		if (bus->clocked) {
			d->load = 1;	/* taken when the master begins the byte */
		} else {
			phy_send(bus, d, bus->cycle);
		}
	}
}

void i2c_phy_edge(twi_bus_t *bus, twi_dev_t *d, int scl_line)
{
	if (!scl_line) {
		return;		/* SDA moving while SCL is low: the next bit */
	}
	if (bus->scl) {
		if (d->phy == TWI_PHY_IDLE) {
			return;
		}
		if (++d->nbits <= 8) {
			if (d->phy != TWI_PHY_TX) {
				d->shift = (uint8_t)(d->shift << 1 | bus->sda);
			}
		} else if (d->phy == TWI_PHY_TX) {
			d->ack = (uint8_t)!bus->sda;		/* the master's */
		}
		return;
	}
	if (d->hold == TWI_HOLD_ADDR && !d->drv.scl_low) {
		twi_bus_drive(bus, &d->drv, d->drv.sda_low, 1, bus->cycle);
	}
	if (d->phy == TWI_PHY_IDLE || d->nbits == 0) {
		return;		/* idle, or the START's own falling edge */
	}
	if (d->nbits < 8) {
		if (d->phy == TWI_PHY_TX) {
			phy_sda(bus, d, !(d->shift & (0x80 >> d->nbits)), bus->cycle);
		}
	} else if (d->nbits == 8) {
		phy_byte_end(bus, d);
	} else {
		phy_ack_end(bus, d);
	}
}

void i2c_phy_released(twi_bus_t *bus, twi_dev_t *d, uint64_t cycle)
{
	if (d->waiting) {
		d->waiting = 0;
		if (d->phy == TWI_PHY_TX) {
			if (!bus->telling) {
				bus->cycle = cycle;
			}
			phy_send(bus, d, cycle);	/* the data before the clock */
		}
	}
	twi_bus_drive(bus, &d->drv, d->drv.sda_low, 0, cycle);
}
