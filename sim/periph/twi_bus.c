/*
 * twi_bus.c: the bus object; it also writes the bus's trace lines, so a bus
 * shared by several simulated boards is traced once.
 */
#include <inttypes.h>
#include <stddef.h>

#include "periph/twi_bus.h"

void twi_bus_init(twi_bus_t *bus, trace_t *trace)
{
	bus->devs = NULL;
	bus->selected = NULL;
	bus->busy = 0;
	bus->trace = trace;
	bus->activity = 0;
	bus->cycle = 0;
	bus->waiter = NULL;
	bus->released_all = 0;
	bus->released_addr = 0;
	bus->sda = bus->scl = bus->scl_ext = 1;
	bus->stuck = 0;
	bus->hold_scl = 0;
	bus->pins = NULL;
	bus->nlisteners = 0;
	bus->busy_signal = NULL;
	twi_fault_arm(&bus->fault, TWI_FAULT_NONE, 0, 0);
}

void twi_bus_attach(twi_bus_t *bus, twi_dev_t *dev)
{
	twi_dev_t **link = &bus->devs;

	while (*link) {
		link = &(*link)->next;
	}
	dev->next = NULL;
	dev->hold = TWI_HOLD_NONE;
	*link = dev;
}

void twi_bus_start(twi_bus_t *bus, uint64_t cycle)
{
	bus->cycle = cycle;
	bus->busy = 1;
	bus->selected = NULL;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi start");
	twi_fault_on_start(&bus->fault);
	if (bus->busy_signal) {
		signal_set(bus->busy_signal, cycle, 1);
	}
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		if (d->ops->bus_start) {
			d->ops->bus_start(d);
		}
	}
}

int twi_bus_address(twi_bus_t *bus, uint64_t cycle, uint8_t addr8)
{
	bus->cycle = cycle;
	bus->selected = NULL;
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		if (d->ops->start(d, addr8) && !bus->selected) {
			bus->selected = d;
		}
	}
	bus->activity++;
	trace_event(bus->trace, cycle, "twi addr %02X %s", addr8,
		    bus->selected ? "ack" : "nack");
	twi_fault_byte_done(&bus->fault);
	return bus->selected != NULL;
}

int twi_bus_write(twi_bus_t *bus, uint64_t cycle, uint8_t byte)
{
	int ack;

	bus->cycle = cycle;
	ack = bus->selected ? bus->selected->ops->write(bus->selected, byte) : 0;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi write %02X %s", byte, ack ? "ack" : "nack");
	twi_fault_byte_done(&bus->fault);
	return ack;
}

uint8_t twi_bus_read(twi_bus_t *bus, uint64_t cycle, int master_acks)
{
	uint8_t byte = 0xff;

	bus->cycle = cycle;
	if (bus->selected) {
		byte = bus->selected->ops->read(bus->selected, master_acks);
	}
	bus->activity++;
	trace_event(bus->trace, cycle, "twi read %02X %s", byte,
		    master_acks ? "ack" : "nack");
	twi_fault_byte_done(&bus->fault);
	return byte;
}

void twi_bus_stop(twi_bus_t *bus, uint64_t cycle)
{
	bus->cycle = cycle;
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		d->ops->stop(d);
	}
	bus->selected = NULL;
	bus->busy = 0;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi stop");
	if (bus->busy_signal) {
		signal_set(bus->busy_signal, cycle, 0);
	}
}

void twi_bus_glitch(twi_bus_t *bus, uint64_t cycle, int start)
{
	twi_dev_t *sel = bus->selected;

	bus->cycle = cycle;
	bus->selected = NULL;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi glitch %s", start ? "start" : "stop");
	twi_fault_byte_done(&bus->fault);
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		if (d == sel && d->ops->bus_error) {
			d->ops->bus_error(d);
		} else if (!start) {
			d->ops->stop(d);
		} else if (d->ops->bus_start) {
			d->ops->bus_start(d);
		}
	}
	bus->busy = start;
	if (bus->busy_signal) {
		signal_set(bus->busy_signal, cycle, start);
	}
}

/* Does a hold HOW stop an operation OP? */
static int twi_bus_blocks(twi_hold_t how, twi_bus_op_t op)
{
	return how == TWI_HOLD_ALL || (how == TWI_HOLD_ADDR && op == TWI_BUS_ADDR);
}

/* SCL as the devices and pins make it, a TWI's clock stretching aside. */
static int twi_bus_scl_ext(const twi_bus_t *bus)
{
	if (bus->hold_scl) {
		return 0;
	}
	for (const twi_pins_t *p = bus->pins; p; p = p->next) {
		if (p->scl_low) {
			return 0;
		}
	}
	return 1;
}

/* Which line stops a master's OP: 'C' (SCL low: nothing moves), 'D' (SDA
 * low: no START), or 0. */
static int twi_bus_line_blocks(const twi_bus_t *bus, twi_bus_op_t op)
{
	if (!twi_bus_scl_ext(bus)) {
		return 'C';
	}
	if (op == TWI_BUS_START && !bus->sda) {
		return 'D';
	}
	return 0;
}

static int twi_bus_blocked(const twi_bus_t *bus, twi_bus_op_t op)
{
	if (twi_bus_line_blocks(bus, op)) {
		return 1;
	}
	for (const twi_dev_t *d = bus->devs; d; d = d->next) {
		if (twi_bus_blocks(d->hold, op)) {
			return 1;
		}
	}
	return 0;
}

uint64_t twi_bus_begin(twi_bus_t *bus, twi_bus_master_t *m, twi_bus_op_t op, uint64_t now)
{
	uint64_t free_at = bus->released_all;
	uint8_t by = bus->released_all_by;

	if (op == TWI_BUS_ADDR && bus->released_addr > free_at) {
		free_at = bus->released_addr;
		by = bus->released_addr_by;
	}
	if (twi_bus_blocked(bus, op)) {
		int line = twi_bus_line_blocks(bus, op);

		if (line) {
			trace_event(bus->trace, now, "twi wait %s", line == 'C' ? "SCL" : "SDA");
		}
		bus->waiter = m;
		bus->waiter_op = op;
		bus->waiter_since = now;
		return 0;
	}
	/* A slave that ran ahead inside the lock-step quantum may have
	 * released after NOW: the operation begins at the release. */
	if (free_at > now) {
		trace_event(bus->trace, free_at, "twi stretch %02X %" PRIu64, by, free_at - now);
		return free_at;
	}
	return now;
}

void twi_bus_cancel(twi_bus_t *bus, twi_bus_master_t *m)
{
	if (bus->waiter == m) {
		bus->waiter = NULL;
	}
}

void twi_bus_hold(twi_bus_t *bus, twi_dev_t *dev, twi_hold_t how)
{
	dev->hold = how;
	twi_bus_lines(bus, bus->cycle);
}

void twi_bus_release(twi_bus_t *bus, twi_dev_t *dev, uint64_t cycle, uint8_t addr8)
{
	twi_hold_t how = dev->hold;

	if (how == TWI_HOLD_NONE) {
		return;
	}
	dev->hold = TWI_HOLD_NONE;
	if (how == TWI_HOLD_ALL && cycle >= bus->released_all) {
		bus->released_all = cycle;
		bus->released_all_by = addr8;
	} else if (how == TWI_HOLD_ADDR && cycle >= bus->released_addr) {
		bus->released_addr = cycle;
		bus->released_addr_by = addr8;
	}
	if (bus->waiter && twi_bus_blocks(how, bus->waiter_op)) {
		if (cycle > bus->waiter_since) {
			trace_event(bus->trace, cycle, "twi stretch %02X %" PRIu64, addr8,
				    cycle - bus->waiter_since);
		}
		if (!twi_bus_blocked(bus, bus->waiter_op)) {
			twi_bus_master_t *m = bus->waiter;
			uint64_t at = cycle > bus->waiter_since ? cycle : bus->waiter_since;

			bus->waiter = NULL;
			m->resume(m, at);
		}
	}
	twi_bus_lines(bus, cycle);
}

/* --- the lines ------------------------------------------------------------- */

void twi_bus_attach_pins(twi_bus_t *bus, twi_pins_t *pins)
{
	pins->sda_low = pins->scl_low = 0;
	pins->next = bus->pins;
	bus->pins = pins;
}

void twi_bus_pins(twi_bus_t *bus, twi_pins_t *pins, int sda_low, int scl_low, uint64_t cycle)
{
	if (pins->sda_low == !!sda_low && pins->scl_low == !!scl_low) {
		return;
	}
	pins->sda_low = !!sda_low;
	pins->scl_low = !!scl_low;
	twi_bus_lines(bus, cycle);
}

int twi_bus_listen(twi_bus_t *bus, twi_line_fn fn, void *param)
{
	if (bus->nlisteners == TWI_BUS_LISTENERS) {
		return -1;
	}
	bus->listener[bus->nlisteners] = fn;
	bus->listener_param[bus->nlisteners++] = param;
	return 0;
}

void twi_bus_stuck(twi_bus_t *bus, uint32_t pulses, uint64_t cycle)
{
	bus->stuck = pulses;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi stuck %" PRIu32, pulses);
	twi_bus_lines(bus, cycle);
}

void twi_bus_hold_scl(twi_bus_t *bus, int on, uint64_t cycle)
{
	bus->hold_scl = !!on;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi hold-scl %s", on ? "on" : "off");
	twi_bus_lines(bus, cycle);
}

void twi_bus_lines(twi_bus_t *bus, uint64_t cycle)
{
	int scl_ext = twi_bus_scl_ext(bus), scl = scl_ext, sda = 1, changed = 0;

	for (const twi_dev_t *d = bus->devs; d; d = d->next) {
		if (d->hold == TWI_HOLD_ALL) {
			scl = 0;	/* clock stretching: not traced as a line */
		}
	}
	if (scl_ext != bus->scl_ext) {
		bus->scl_ext = scl_ext;
		changed = 1;
		trace_event(bus->trace, cycle, "twi line SCL %d", scl_ext);
	}
	if (scl != bus->scl) {
		bus->scl = scl;
		changed = 1;
		if (!scl && bus->stuck && --bus->stuck == 0) {
			trace_event(bus->trace, cycle, "twi stuck 0");
		}
	}
	sda = !bus->stuck;
	for (const twi_pins_t *p = bus->pins; p; p = p->next) {
		if (p->sda_low) {
			sda = 0;
		}
	}
	if (sda != bus->sda) {
		bus->sda = sda;
		changed = 1;
		trace_event(bus->trace, cycle, "twi line SDA %d", sda);
	}
	if (!changed) {
		return;
	}
	bus->activity++;
	for (int i = 0; i < bus->nlisteners; i++) {
		bus->listener[i](bus->listener_param[i], cycle);
	}
	if (bus->waiter && !twi_bus_blocked(bus, bus->waiter_op)) {
		twi_bus_master_t *m = bus->waiter;
		uint64_t at = cycle > bus->waiter_since ? cycle : bus->waiter_since;

		bus->waiter = NULL;
		m->resume(m, at);
	}
}
