/*
 * twi_bus.c: the lines, their drivers and listeners (twi_bus.h); it also
 * writes the bus's trace lines, so a bus shared by several simulated boards
 * is traced once.
 */
#include <inttypes.h>
#include <stddef.h>

#include "periph/i2c_phy.h"
#include "periph/twi_bus.h"

void twi_bus_init(twi_bus_t *bus, trace_t *trace)
{
	*bus = (twi_bus_t) {
		.trace = trace,
		.sda = 1, .scl = 1, .sda_ext = 1, .scl_ext = 1,
		.stuck_drv = { .ext = 1 }, .hold_drv = { .ext = 1 }, .rival_drv = { .ext = 1 },
	};
}

void twi_bus_attach(twi_bus_t *bus, twi_dev_t *dev)
{
	twi_dev_t **link = &bus->devs;

	while (*link) {
		link = &(*link)->next;
	}
	dev->next = NULL;
	dev->hold = TWI_HOLD_NONE;
	dev->drv = (twi_drv_t) { 0 };
	dev->phy = TWI_PHY_IDLE;
	*link = dev;
}

void twi_bus_attach_drv(twi_bus_t *bus, twi_drv_t *d, int ext)
{
	(void)bus;
	*d = (twi_drv_t) { .ext = (uint8_t)!!ext };
}

/* --- telling the edges ------------------------------------------------------ */

static void twi_bus_resume(twi_bus_t *bus, uint64_t cycle)
{
	twi_bus_master_t *m = bus->waiter;
	uint64_t at = cycle > bus->waiter_since ? cycle : bus->waiter_since;

	bus->waiter = NULL;
	bus->waiting = TWI_WAIT_NONE;
	m->resume(m, at);
}

/* Has what the waiting master waits for come? */
static int twi_bus_wait_over(const twi_bus_t *bus)
{
	switch (bus->waiting) {
	case TWI_WAIT_SCL_HIGH:
		return bus->scl;
	case TWI_WAIT_SCL_FREE:
		return !twi_bus_scl_held(bus, bus->waiter_drv);
	case TWI_WAIT_BUS_FREE:
		return bus->scl && bus->sda;
	default:
		return 0;
	}
}

/* One line changed level at CYCLE: tell everyone. */
static void twi_bus_edge(twi_bus_t *bus, int scl_line, uint64_t cycle)
{
	bus->cycle = cycle;
	bus->activity++;
	if (scl_line) {
		if (bus->scl_signal) {
			signal_set(bus->scl_signal, cycle, bus->scl);
		}
		if (!bus->scl && bus->stuck && --bus->stuck == 0) {
			trace_event(bus->trace, cycle, "twi stuck 0");
			twi_bus_drive(bus, &bus->stuck_drv, 0, 0, cycle);
		}
	} else if (bus->sda_signal) {
		signal_set(bus->sda_signal, cycle, bus->sda);
	}
	for (int i = 0; i < bus->nlisteners; i++) {
		bus->listener[i](bus->listener_param[i], scl_line, cycle);
	}
	if (!scl_line && bus->scl) {
		/* SDA changed with SCL high: START (falling) or STOP (rising) */
		twi_bus_master_t *m = bus->in_byte;

		for (twi_dev_t *d = bus->devs; d; d = d->next) {
			i2c_phy_condition(bus, d, !bus->sda);
		}
		if (m) {
			bus->in_byte = NULL;
			m->condition(m, cycle);
		}
	} else if (bus->nactive) {
		for (twi_dev_t *d = bus->devs; d; d = d->next) {
			if (d->phy != TWI_PHY_IDLE || d->hold == TWI_HOLD_ADDR) {
				i2c_phy_edge(bus, d, scl_line);
			}
		}
	}
	if (bus->waiter && twi_bus_wait_over(bus)) {
		twi_bus_resume(bus, cycle);
	}
}

/* The drivers changed at CYCLE: trace the ext lines, tell the edges. A
 * change made while telling is told by the loop of the outer call. */
static void twi_bus_lines(twi_bus_t *bus, uint64_t cycle)
{
	int scl_ext = !bus->ext_scl_lows, sda_ext = !bus->ext_sda_lows;

	if (scl_ext != bus->scl_ext) {
		bus->scl_ext = scl_ext;
		trace_event(bus->trace, cycle, "twi line SCL %d", scl_ext);
	}
	if (sda_ext != bus->sda_ext) {
		bus->sda_ext = sda_ext;
		trace_event(bus->trace, cycle, "twi line SDA %d", sda_ext);
	}
	if (bus->telling) {
		if (cycle > bus->cycle) {
			bus->cycle = cycle;
		}
		return;
	}
	bus->telling = 1;
	for (;;) {
		int scl = !bus->scl_lows, sda = !bus->sda_lows;

		if (scl != bus->scl) {
			bus->scl = scl;
			twi_bus_edge(bus, 1, cycle > bus->cycle ? cycle : bus->cycle);
		} else if (sda != bus->sda) {
			bus->sda = sda;
			twi_bus_edge(bus, 0, cycle > bus->cycle ? cycle : bus->cycle);
		} else {
			break;
		}
	}
	bus->telling = 0;
	if (bus->waiter && twi_bus_wait_over(bus)) {
		twi_bus_resume(bus, cycle > bus->cycle ? cycle : bus->cycle);
	}
}

void twi_bus_drive(twi_bus_t *bus, twi_drv_t *d, int sda_low, int scl_low, uint64_t cycle)
{
	int ds = !!sda_low - d->sda_low, dc = !!scl_low - d->scl_low;

	if (!ds && !dc) {
		return;
	}
	d->sda_low = (uint8_t)!!sda_low;
	d->scl_low = (uint8_t)!!scl_low;
	bus->sda_lows += ds;
	bus->scl_lows += dc;
	if (d->ext) {
		bus->ext_sda_lows += ds;
		bus->ext_scl_lows += dc;
	}
	twi_bus_lines(bus, cycle);
}

/* --- the master ---------------------------------------------------------------- */

void twi_bus_wait(twi_bus_t *bus, twi_bus_master_t *m, twi_drv_t *d, twi_wait_t what,
		  uint64_t now)
{
	bus->waiter = m;
	bus->waiter_drv = d;
	bus->waiting = what;
	bus->waiter_since = now;
}

void twi_bus_cancel(twi_bus_t *bus, twi_bus_master_t *m)
{
	if (bus->waiter == m) {
		bus->waiter = NULL;
		bus->waiting = TWI_WAIT_NONE;
	}
}

void twi_bus_byte(twi_bus_t *bus, uint64_t begin, uint64_t end)
{
	bus->byte_end = end;
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		if (d->load) {
			i2c_phy_load(bus, d, begin);
		}
	}
}

void twi_bus_note_start(twi_bus_t *bus, uint64_t cycle)
{
	bus->clocked = 1;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi start");
	twi_fault_on_start(&bus->fault);
	if (bus->busy_signal) {
		signal_set(bus->busy_signal, cycle, 1);
	}
}

/* One byte's trace line; the bus and the fault count it. */
static void twi_bus_note_byte(twi_bus_t *bus, uint64_t cycle, const char *what, uint8_t byte,
			      int ack)
{
	bus->activity++;
	bus->bytes++;
	trace_event(bus->trace, cycle, "twi %s %02X %s", what, byte, ack ? "ack" : "nack");
	twi_fault_byte_done(&bus->fault);
}

void twi_bus_note_addr(twi_bus_t *bus, uint64_t cycle, uint8_t addr8, int ack)
{
	twi_bus_note_byte(bus, cycle, "addr", addr8, ack);
}

void twi_bus_note_write(twi_bus_t *bus, uint64_t cycle, uint8_t byte, int ack)
{
	twi_bus_note_byte(bus, cycle, "write", byte, ack);
}

void twi_bus_note_read(twi_bus_t *bus, uint64_t cycle, uint8_t byte, int master_acks)
{
	twi_bus_note_byte(bus, cycle, "read", byte, master_acks);
}

void twi_bus_note_stop(twi_bus_t *bus, uint64_t cycle)
{
	bus->clocked = 0;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi stop");
	if (twi_fault_on_stop(&bus->fault)) {
		trace_event(bus->trace, cycle, "twi fault missed");
	}
	if (bus->busy_signal) {
		signal_set(bus->busy_signal, cycle, 0);
	}
}

void twi_bus_glitch(twi_bus_t *bus, uint64_t cycle, int start)
{
	bus->cycle = cycle;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi glitch %s", start ? "start" : "stop");
	twi_fault_byte_done(&bus->fault);
	/* every device hears the condition first; what their fronts let go
	 * of then is told after */
	bus->telling = 1;
	for (twi_dev_t *d = bus->devs; d; d = d->next) {
		i2c_phy_condition(bus, d, start);
	}
	bus->telling = 0;
	twi_bus_lines(bus, cycle);
}

/* --- devices' holds ------------------------------------------------------------ */

void twi_bus_hold(twi_bus_t *bus, twi_dev_t *dev, twi_hold_t how)
{
	dev->hold = how;
	if (how == TWI_HOLD_ALL) {
		twi_bus_drive(bus, &dev->drv, dev->drv.sda_low, 1, bus->cycle);
	}
}

void twi_bus_release(twi_bus_t *bus, twi_dev_t *dev, uint64_t cycle, uint8_t addr8)
{
	int held = dev->drv.scl_low;

	if (dev->hold == TWI_HOLD_NONE) {
		return;
	}
	dev->hold = TWI_HOLD_NONE;
	if (!held) {
		return;		/* a TWI_HOLD_ADDR whose falling edge never came */
	}
	if (cycle >= bus->scl_free_at) {
		bus->scl_free_at = cycle;
		bus->scl_free_by = addr8;
	}
	if (bus->waiter && bus->waiting == TWI_WAIT_SCL_FREE && cycle > bus->waiter_since) {
		trace_event(bus->trace, cycle, "twi stretch %02X %" PRIu64, addr8,
			    cycle - bus->waiter_since);
	}
	i2c_phy_released(bus, dev, cycle);
}

void twi_bus_forget(twi_bus_t *bus, twi_dev_t *dev, uint64_t cycle)
{
	i2c_phy_state(bus, dev, TWI_PHY_IDLE);
	dev->hold = TWI_HOLD_NONE;
	dev->waiting = 0;
	dev->load = 0;
	twi_bus_drive(bus, &dev->drv, 0, 0, cycle);
}

/* --- listeners, fault devices -------------------------------------------------- */

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
	twi_bus_drive(bus, &bus->stuck_drv, pulses != 0, 0, cycle);
}

void twi_bus_hold_scl(twi_bus_t *bus, int on, uint64_t cycle)
{
	bus->hold_scl = !!on;
	bus->activity++;
	trace_event(bus->trace, cycle, "twi hold-scl %s", on ? "on" : "off");
	twi_bus_drive(bus, &bus->hold_drv, 0, on, cycle);
}
