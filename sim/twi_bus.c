/*
 * twi_bus.c: the bus object; it also writes the bus's trace lines, so a bus
 * shared by several simulated boards is traced once.
 */
#include <stddef.h>

#include "twi_bus.h"

void twi_bus_init(twi_bus_t *bus, trace_t *trace)
{
	bus->devs = NULL;
	bus->selected = NULL;
	bus->busy = 0;
	bus->trace = trace;
	bus->activity = 0;
	bus->now = 0;
}

void twi_bus_attach(twi_bus_t *bus, twi_dev_t *dev)
{
	twi_dev_t **link = &bus->devs;

	while (*link) {
		link = &(*link)->next;
	}
	dev->next = NULL;
	*link = dev;
}

void twi_bus_start(twi_bus_t *bus, uint64_t cycle)
{
	bus->busy = 1;
	bus->selected = NULL;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi start");
}

int twi_bus_address(twi_bus_t *bus, uint64_t cycle, uint8_t addr8)
{
	bus->selected = NULL;
	bus->now = cycle;
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		if (d->ops->start(d, addr8) && !bus->selected) {
			bus->selected = d;
		}
	}
	bus->activity++;
	trace_event(bus->trace, cycle, "twi addr %02X %s", addr8,
		    bus->selected ? "ack" : "nack");
	return bus->selected != NULL;
}

int twi_bus_write(twi_bus_t *bus, uint64_t cycle, uint8_t byte)
{
	bus->now = cycle;
	int ack = bus->selected ? bus->selected->ops->write(bus->selected, byte) : 0;

	bus->activity++;
	trace_event(bus->trace, cycle, "twi write %02X %s", byte, ack ? "ack" : "nack");
	return ack;
}

uint8_t twi_bus_read(twi_bus_t *bus, uint64_t cycle, int master_acks)
{
	uint8_t byte = 0xff;

	bus->now = cycle;
	if (bus->selected) {
		byte = bus->selected->ops->read(bus->selected, master_acks);
	}
	bus->activity++;
	trace_event(bus->trace, cycle, "twi read %02X %s", byte,
		    master_acks ? "ack" : "nack");
	return byte;
}

void twi_bus_stop(twi_bus_t *bus, uint64_t cycle)
{
	bus->now = cycle;
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		d->ops->stop(d);
	}
	bus->selected = NULL;
	bus->busy = 0;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi stop");
}
