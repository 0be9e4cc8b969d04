/*
 * twi.c: TWI model, master and slave mode (twi.h).
 */
#include <stddef.h>
#include <string.h>

#include "sim_regbit.h"
#include "avr_ioport.h"

#include "periph/io_hook.h"
#include "periph/sim_twi.h"
#include "periph/avr_libc_twi.h"

/* TWCR bits (the datasheet's names; avr-libc has them only per MCU). */
enum {
	TWCR_TWINT = 7, TWCR_TWEA = 6, TWCR_TWSTA = 5, TWCR_TWSTO = 4,
	TWCR_TWWC = 3, TWCR_TWEN = 2, TWCR_TWIE = 0,
};

#define BIT(b) (1u << (b))
#define TWSR_TWPS 0x03

static inline uint8_t *twi_reg(const sim_twi_t *t, uint16_t addr)
{
	return &t->avr->data[addr];
}

avr_cycle_count_t sim_twi_scl_period(const sim_twi_t *t)
{
	unsigned twps = *twi_reg(t, t->regs->twsr) & TWSR_TWPS;

	return 16 + 2 * (avr_cycle_count_t)*twi_reg(t, t->regs->twbr) * (1u << (2 * twps));
}

/* TWINT is a level: while it and TWIE are set the interrupt is requested
 * (the ISR does not clear it; see usart.c for the re-raise scheme). */
static void twi_sync(sim_twi_t *t)
{
	uint8_t cr = *twi_reg(t, t->regs->twcr);
	avr_int_vector_t *v = &t->vect_twi;

	*twi_reg(t, t->regs->twsr) = (uint8_t)(t->status |
					       (*twi_reg(t, t->regs->twsr) & TWSR_TWPS));
	if (cr & BIT(TWCR_TWINT)) {
		if (!v->pending && (cr & BIT(TWCR_TWIE))) {
			avr_raise_interrupt(t->avr, v);
		}
	} else if (v->pending) {
		avr_clear_interrupt(t->avr, v);
	}
}

static void twi_done(sim_twi_t *t, uint8_t status)
{
	t->status = status;
	t->op = TWI_OP_NONE;
	*twi_reg(t, t->regs->twcr) |= BIT(TWCR_TWINT);
	twi_sync(t);
}

/* The master lost arbitration in the byte that ended at WHEN (twi_fault.h):
 * it let SDA go from the lost bit on and clocked the byte to its end; it is
 * not the master any more: 0x38. */
static void twi_arb_lost(sim_twi_t *t, avr_cycle_count_t when)
{
	trace_event(t->bus->trace, when, "twi arb-lost");
	t->owner = 0;
	twi_done(t, TW_MT_ARB_LOST);
}

/* The master lost arbitration in its address byte: the address the devices
 * read (SEEN) goes to them all, this TWI among them now that it is no
 * longer the master; addressed (its TWAR, TWEA set) it is a slave from
 * here, 0x68 (written to) or 0xB0 (read from), else 0x38. (No general
 * call: 0x78 is not modelled.) */
static void twi_arb_lost_addr(sim_twi_t *t, avr_cycle_count_t when, uint8_t seen)
{
	t->owner = 0;
	t->op = TWI_OP_NONE;
	twi_bus_address(t->bus, when, seen);
	if (!t->addressed) {
		twi_arb_lost(t, when);
		return;
	}
	trace_event(t->bus->trace, when, "twi arb-lost %02X", t->sl_addr);
	t->status = t->sl_status = t->addressed == TWI_SLAVE_TX ? TW_ST_ARB_LOST_SLA_ACK
							       : TW_SR_ARB_LOST_SLA_ACK;
	twi_sync(t);
}

/* A START or STOP in the middle of the byte under way, at t->glitch_at:
 * a bus error. The TWI stops and lets the lines go, TWINT rises with 0x00;
 * the firmware recovers with TWSTO (or TWEN off). */
static void twi_glitch(sim_twi_t *t)
{
	int start = t->op_fault == TWI_FAULT_START;
	avr_cycle_count_t at = t->glitch_at;

	t->op_fault = TWI_FAULT_NONE;
	twi_bus_glitch(t->bus, at, start);
	trace_event(t->bus->trace, at, "twi bus-error");
	t->owner = 0;
	twi_done(t, TW_BUS_ERROR);
}

static avr_cycle_count_t twi_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	sim_twi_t *t = param;
	uint8_t *twcr = twi_reg(t, t->regs->twcr);
	uint8_t *twdr = twi_reg(t, t->regs->twdr);
	int ack, lost = 0;
	unsigned bit = 0;
	twi_fault_kind_t fault;
	uint8_t sent;

	(void)avr;
	/* The bus events carry the exact completion cycle, not the cycle
	 * simavr got round to calling us (1-4 later). */
	when = t->op_end;
	if (t->op_fault != TWI_FAULT_NONE) {
		twi_glitch(t);
		return 0;
	}
	if (t->op != TWI_OP_NONE && !t->bus->scl_ext) {
		/* SCL held low under the operation: its clock stops; it ends
		 * one period after the release (the bit position is not kept). */
		t->op_periods = 1;
		if (!twi_bus_begin(t->bus, &t->master, TWI_BUS_DATA, when)) {
			return 0;
		}
	}
	switch (t->op) {
	case TWI_OP_START:
		twi_bus_start(t->bus, when);
		twi_done(t, t->owner ? TW_REP_START : TW_START);
		t->owner = 1;
		break;
	case TWI_OP_STOP:
	case TWI_OP_STOP_START:
		twi_bus_stop(t->bus, when);
		t->owner = 0;
		*twcr &= (uint8_t)~BIT(TWCR_TWSTO);
		t->status = TW_NO_INFO;
		if (t->op == TWI_OP_STOP_START) {
			/* nothing holds SCL right after a STOP (twi_bus.h) */
			t->op = TWI_OP_START;
			t->op_end = when + sim_twi_scl_period(t);
			return t->op_end;
		}
		t->op = TWI_OP_NONE;
		twi_sync(t);	/* no TWINT after a STOP */
		break;
	case TWI_OP_SLA:
		fault = twi_fault_here(&t->bus->fault, &bit);
		sent = fault == TWI_FAULT_ARB ? twi_fault_arb_sent(*twdr, bit, &lost) : *twdr;
		if (lost) {
			twi_arb_lost_addr(t, when, sent);
			break;
		}
		ack = twi_bus_address(t->bus, when, sent) || (fault == TWI_FAULT_ARB && bit == 8);
		if (*twdr & 1) {
			twi_done(t, ack ? TW_MR_SLA_ACK : TW_MR_SLA_NACK);
		} else {
			twi_done(t, ack ? TW_MT_SLA_ACK : TW_MT_SLA_NACK);
		}
		break;
	case TWI_OP_TX:
		fault = twi_fault_here(&t->bus->fault, &bit);
		sent = fault == TWI_FAULT_ARB ? twi_fault_arb_sent(*twdr, bit, &lost) : *twdr;
		ack = twi_bus_write(t->bus, when, sent) || (fault == TWI_FAULT_ARB && bit == 8);
		if (lost) {
			twi_arb_lost(t, when);
		} else {
			twi_done(t, ack ? TW_MT_DATA_ACK : TW_MT_DATA_NACK);
		}
		break;
	case TWI_OP_RX:
		/* the rival's low bit: a 0 read, or an ACK where the master
		 * sends its NACK (it loses arbitration there) */
		fault = twi_fault_here(&t->bus->fault, &bit);
		lost = fault == TWI_FAULT_ARB && bit == 8 && !t->op_ack;
		*twdr = twi_bus_read(t->bus, when, t->op_ack || lost);
		if (fault == TWI_FAULT_ARB && bit < 8) {
			*twdr = twi_fault_arb_read(*twdr, bit);
		}
		if (lost) {
			twi_arb_lost(t, when);
		} else {
			twi_done(t, t->op_ack ? TW_MR_DATA_ACK : TW_MR_DATA_NACK);
		}
		break;
	case TWI_OP_NONE:
		break;
	}
	return 0;
}

/* The operation in progress begins on the bus at cycle START. */
static void twi_schedule(sim_twi_t *t, avr_cycle_count_t start)
{
	avr_cycle_count_t now = t->avr->cycle, p = sim_twi_scl_period(t), at;
	unsigned bit;

	t->op_end = start + t->op_periods * p;
	at = t->op_end;
	/* a glitch armed for this byte: in SCL's high half of its bit */
	t->op_fault = TWI_FAULT_NONE;
	if (t->op_periods == 9) {
		twi_fault_kind_t f = twi_fault_here(&t->bus->fault, &bit);

		if (f == TWI_FAULT_START || f == TWI_FAULT_STOP) {
			t->op_fault = f;
			t->glitch_at = at = start + bit * p + 3 * p / 4;
		}
	}
	avr_cycle_timer_register(t->avr, at > now ? at - now : 1, twi_timer, t);
}

static void twi_master_resume(twi_bus_master_t *m, uint64_t cycle)
{
	sim_twi_t *t = (sim_twi_t *)((char *)m - offsetof(sim_twi_t, master));

	if (t->op != TWI_OP_NONE) {
		twi_schedule(t, cycle);
	}
}

/* Start OP, PERIODS SCL periods long, as soon as no slave holds SCL. */
static void twi_begin(sim_twi_t *t, sim_twi_op_t op, avr_cycle_count_t periods)
{
	twi_bus_op_t kind = TWI_BUS_DATA;
	uint64_t at;

	switch (op) {
	case TWI_OP_START:
		kind = TWI_BUS_START;
		break;
	case TWI_OP_STOP:
	case TWI_OP_STOP_START:
		kind = TWI_BUS_STOP;
		break;
	case TWI_OP_SLA:
		kind = TWI_BUS_ADDR;
		break;
	default:
		break;
	}
	t->op = op;
	t->op_periods = periods;
	t->op_end = 0;
	at = twi_bus_begin(t->bus, &t->master, kind, t->avr->cycle);
	if (at) {
		twi_schedule(t, at);
	}
}

/* --- slave mode ----------------------------------------------------------- */

static void twi_slave_rise(sim_twi_t *t)
{
	t->sl_pending = 0;
	t->status = t->sl_status;
	if (t->sl_has_data) {
		*twi_reg(t, t->regs->twdr) = t->sl_data;
	}
	*twi_reg(t, t->regs->twcr) |= BIT(TWCR_TWINT);
	twi_sync(t);
}

static avr_cycle_count_t twi_slave_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	(void)avr;
	(void)when;
	twi_slave_rise(param);
	return 0;
}

/* A bus event for this slave completed at the bus's cycle: TWINT rises
 * then with STATUS (and DATA in TWDR), and SCL is held low until the
 * firmware clears TWINT. This board may be behind the master inside the
 * lock-step quantum: then the rise waits for its cycle. */
static void twi_slave_deliver(sim_twi_t *t, uint8_t status, int has_data, uint8_t data,
			      twi_hold_t hold)
{
	uint64_t at = t->bus->cycle;

	twi_bus_hold(t->bus, &t->dev, hold);
	t->sl_status = status;
	t->sl_has_data = has_data;
	t->sl_data = data;
	t->sl_at = at;
	if (t->avr->cycle >= at) {
		twi_slave_rise(t);
	} else {
		t->sl_pending = 1;
		avr_cycle_timer_register(t->avr, at - t->avr->cycle, twi_slave_timer, t);
	}
}

/* The firmware cleared TWINT (CR: the value written) while holding SCL. */
static void twi_slave_release(sim_twi_t *t, uint8_t cr)
{
	t->sl_ea = !!(cr & BIT(TWCR_TWEA));
	t->sl_tx = *twi_reg(t, t->regs->twdr);
	t->status = TW_NO_INFO;
	twi_bus_release(t->bus, &t->dev, t->avr->cycle, t->sl_addr);
}

/* TWI off or reset: forget the transfer, let SCL go. */
static void twi_slave_abandon(sim_twi_t *t)
{
	if (t->sl_pending) {
		avr_cycle_timer_cancel(t->avr, twi_slave_timer, t);
		t->sl_pending = 0;
	}
	t->addressed = 0;
	twi_bus_release(t->bus, &t->dev, t->avr->cycle, t->sl_addr);
}

static sim_twi_t *twi_of_dev(twi_dev_t *dev)
{
	return (sim_twi_t *)((char *)dev - offsetof(sim_twi_t, dev));
}

static int twi_dev_start(twi_dev_t *dev, uint8_t addr8)
{
	sim_twi_t *t = twi_of_dev(dev);
	uint8_t cr = *twi_reg(t, t->regs->twcr);
	uint8_t twar = *twi_reg(t, t->regs->twar);

	/* A master never answers its own address; a slave answers only while
	 * enabled with TWEA and idle (the bus waits for a TWINT it holds). */
	if (t->owner || t->op != TWI_OP_NONE || t->sl_pending || dev->hold ||
	    !(cr & BIT(TWCR_TWEN)) || !(cr & BIT(TWCR_TWEA)) || (cr & BIT(TWCR_TWINT)) ||
	    (addr8 & 0xfe) != (twar & 0xfe)) {
		return 0;
	}
	t->sl_addr = addr8 & 0xfe;
	if (addr8 & 1) {
		t->addressed = TWI_SLAVE_TX;
		twi_slave_deliver(t, TW_ST_SLA_ACK, 0, 0, TWI_HOLD_ALL);
	} else {
		t->addressed = TWI_SLAVE_RX;
		twi_slave_deliver(t, TW_SR_SLA_ACK, 0, 0, TWI_HOLD_ALL);
	}
	return 1;
}

static int twi_dev_write(twi_dev_t *dev, uint8_t byte)
{
	sim_twi_t *t = twi_of_dev(dev);

	if (t->addressed != TWI_SLAVE_RX) {
		return 0;
	}
	if (t->sl_ea) {
		twi_slave_deliver(t, TW_SR_DATA_ACK, 1, byte, TWI_HOLD_ALL);
		return 1;
	}
	/* NACKed: not addressed any more until the next START */
	t->addressed = 0;
	twi_slave_deliver(t, TW_SR_DATA_NACK, 1, byte, TWI_HOLD_ALL);
	return 0;
}

static uint8_t twi_dev_read(twi_dev_t *dev, int master_acks)
{
	sim_twi_t *t = twi_of_dev(dev);
	uint8_t byte = t->sl_tx;
	uint8_t status;

	if (t->addressed != TWI_SLAVE_TX) {
		return 0xff;		/* SDA released: pull-ups */
	}
	if (!master_acks) {
		status = TW_ST_DATA_NACK;
	} else if (t->sl_ea) {
		status = TW_ST_DATA_ACK;
	} else {
		status = TW_ST_LAST_DATA;
	}
	if (status != TW_ST_DATA_ACK) {
		t->addressed = 0;
	}
	twi_slave_deliver(t, status, 0, 0, TWI_HOLD_ALL);
	return byte;
}

/* STOP, or a repeated START, ends a transfer this slave takes part in. */
static void twi_dev_end(twi_dev_t *dev)
{
	sim_twi_t *t = twi_of_dev(dev);

	if (t->addressed == TWI_SLAVE_RX) {
		t->addressed = 0;
		twi_slave_deliver(t, TW_SR_STOP, 0, 0, TWI_HOLD_ADDR);
	} else {
		/* the datasheet gives a transmitter no code for it */
		t->addressed = 0;
	}
}

/* A START or STOP in the middle of a byte of this slave's transfer: TWINT
 * with 0x00, the lines let go, not addressed; the firmware recovers with
 * TWSTO (twi_action). */
static void twi_dev_bus_error(twi_dev_t *dev)
{
	sim_twi_t *t = twi_of_dev(dev);

	trace_event(t->bus->trace, t->bus->cycle, "twi bus-error %02X", t->sl_addr);
	t->addressed = 0;
	twi_slave_deliver(t, TW_BUS_ERROR, 0, 0, TWI_HOLD_NONE);
}

static const twi_dev_ops_t twi_dev_ops = {
	.start = twi_dev_start,
	.write = twi_dev_write,
	.read = twi_dev_read,
	.stop = twi_dev_end,
	.bus_start = twi_dev_end,
	.bus_error = twi_dev_bus_error,
};

/* --- the pins ------------------------------------------------------------- */

/* This board's pull on the lines: with TWEN set the TWI owns the pins (its
 * own SCL holds are the bus device's); with TWEN off, the port pins. */
static void twi_pins_update(sim_twi_t *t)
{
	int sda_low = 0, scl_low = 0;

	if (t->pins_wired && !(*twi_reg(t, t->regs->twcr) & BIT(TWCR_TWEN))) {
		uint8_t low = (uint8_t)(t->pin_ddr & ~t->pin_port);

		scl_low = !!(low & BIT(t->pin_scl));
		sda_low = !!(low & BIT(t->pin_sda));
	}
	twi_bus_pins(t->bus, &t->pins, sda_low, scl_low, t->avr->cycle);
}

static void twi_on_port(struct avr_irq_t *irq, uint32_t value, void *param)
{
	sim_twi_t *t = param;

	(void)irq;
	t->pin_port = (uint8_t)value;
	twi_pins_update(t);
}

static void twi_on_ddr(struct avr_irq_t *irq, uint32_t value, void *param)
{
	sim_twi_t *t = param;

	(void)irq;
	t->pin_ddr = (uint8_t)value;
	twi_pins_update(t);
}

int sim_twi_wire_pins(sim_twi_t *t, char port, int scl, int sda)
{
	avr_irq_t *irq = avr_io_getirq(t->avr, AVR_IOCTL_IOPORT_GETIRQ(port), 0);

	if (!irq) {
		return -1;
	}
	t->pins_wired = 1;
	t->pin_scl = (uint8_t)scl;
	t->pin_sda = (uint8_t)sda;
	avr_irq_register_notify(irq + IOPORT_IRQ_REG_PORT, twi_on_port, t);
	avr_irq_register_notify(irq + IOPORT_IRQ_DIRECTION_ALL, twi_on_ddr, t);
	return 0;
}

/* TWINT was cleared with TWEN set: start what TWSTA/TWSTO and the state
 * ask for. */
static void twi_action(sim_twi_t *t, uint8_t cr)
{
	int sta = !!(cr & BIT(TWCR_TWSTA));
	int sto = !!(cr & BIT(TWCR_TWSTO));

	if (sto) {
		if (t->owner) {
			twi_begin(t, sta ? TWI_OP_STOP_START : TWI_OP_STOP, 1);
			return;
		}
		/* Not the master: TWSTO only recovers from a bus error. */
		*twi_reg(t, t->regs->twcr) &= (uint8_t)~BIT(TWCR_TWSTO);
		t->status = TW_NO_INFO;
	}
	if (sta) {
		twi_begin(t, TWI_OP_START, 1);
		return;
	}
	switch (t->status) {
	case TW_START:
	case TW_REP_START:
		twi_begin(t, TWI_OP_SLA, 9);
		break;
	case TW_MT_SLA_ACK:
	case TW_MT_SLA_NACK:
	case TW_MT_DATA_ACK:
	case TW_MT_DATA_NACK:
		twi_begin(t, TWI_OP_TX, 9);
		break;
	case TW_MR_SLA_ACK:
	case TW_MR_DATA_ACK:
		t->op_ack = !!(cr & BIT(TWCR_TWEA));
		twi_begin(t, TWI_OP_RX, 9);
		break;
	default:
		/* After 48/58 only START/STOP are defined; when idle, the TWI
		 * waits to be addressed as a slave (twi_dev_ops). */
		break;
	}
}

static void twi_write_twcr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	sim_twi_t *t = param;
	uint8_t old = avr->data[addr];
	uint8_t keep = old & (BIT(TWCR_TWINT) | BIT(TWCR_TWWC));
	uint8_t cr = (uint8_t)(v & ~(BIT(TWCR_TWINT) | BIT(TWCR_TWWC) | 0x02));
	int clear_int = !!(v & BIT(TWCR_TWINT));

	/* TWSTO stays set by hardware until its STOP is on the bus. */
	if (t->op == TWI_OP_STOP || t->op == TWI_OP_STOP_START) {
		cr |= BIT(TWCR_TWSTO);
	}
	if (clear_int && t->dev.hold && (old & BIT(TWCR_TWINT)) && !t->sl_pending) {
		twi_slave_release(t, (uint8_t)v);
	}
	if (clear_int) {
		keep &= (uint8_t)~BIT(TWCR_TWINT);
	}
	avr->data[addr] = (uint8_t)(keep | cr);

	if (!(v & BIT(TWCR_TWEN))) {
		/* TWI off: transfers end, the lines are released. */
		if (t->op != TWI_OP_NONE || t->owner) {
			trace_event(t->bus->trace, avr->cycle, "twi off");
		} else if (t->addressed) {
			trace_event(t->bus->trace, avr->cycle, "twi off %02X", t->sl_addr);
		}
		avr_cycle_timer_cancel(avr, twi_timer, t);
		twi_bus_cancel(t->bus, &t->master);
		twi_slave_abandon(t);
		t->op = TWI_OP_NONE;
		t->owner = 0;
		t->status = TW_NO_INFO;
		avr->data[addr] &= (uint8_t)~(BIT(TWCR_TWSTA) | BIT(TWCR_TWSTO));
	} else if (t->op == TWI_OP_NONE &&
		   (clear_int || (!(keep & BIT(TWCR_TWINT)) && !t->owner &&
				  (cr & BIT(TWCR_TWSTA))))) {
		twi_action(t, cr);
	}
	twi_sync(t);
	if (!(old & BIT(TWCR_TWEN)) != !(v & BIT(TWCR_TWEN))) {
		twi_pins_update(t);
	}
}

static void twi_write_twdr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	sim_twi_t *t = param;
	uint8_t *twcr = twi_reg(t, t->regs->twcr);

	if (*twcr & BIT(TWCR_TWINT)) {
		avr->data[addr] = v;
		*twcr &= (uint8_t)~BIT(TWCR_TWWC);
	} else {
		*twcr |= BIT(TWCR_TWWC);
	}
}

static void twi_write_twsr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	sim_twi_t *t = param;

	avr->data[addr] = (uint8_t)(t->status | (v & TWSR_TWPS));
}

static void twi_write_plain(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	(void)param;
	avr->data[addr] = v;
}

static void twi_irq_running(struct avr_irq_t *irq, uint32_t value, void *param)
{
	(void)irq;
	(void)value;
	twi_sync(param);
}

static void twi_reset(avr_io_t *io)
{
	sim_twi_t *t = (sim_twi_t *)io;
	avr_t *avr = t->avr;

	/* simavr wiped the cycle timers already */
	t->sl_pending = 0;
	twi_bus_cancel(t->bus, &t->master);
	twi_slave_abandon(t);
	t->op = TWI_OP_NONE;
	t->owner = 0;
	t->status = TW_NO_INFO;
	avr->data[t->regs->twbr] = 0;
	avr->data[t->regs->twsr] = TW_NO_INFO;
	avr->data[t->regs->twar] = 0xfe;
	avr->data[t->regs->twdr] = 0xff;
	avr->data[t->regs->twcr] = 0;
	twi_sync(t);
	/* avr_reset cleared the ports without telling their IRQs */
	t->pin_ddr = t->pin_port = 0;
	twi_pins_update(t);
}

void sim_twi_init(sim_twi_t *t, avr_t *avr, const sim_mcu_twi_t *regs, twi_bus_t *bus)
{
	memset(t, 0, sizeof(*t));
	t->avr = avr;
	t->regs = regs;
	t->bus = bus;
	t->io.kind = "orfa-twi";
	t->io.reset = twi_reset;
	t->master.resume = twi_master_resume;
	t->dev.ops = &twi_dev_ops;
	t->dev.name = "avr-twi";
	twi_bus_attach(bus, &t->dev);
	twi_bus_attach_pins(bus, &t->pins);

	t->vect_twi = (avr_int_vector_t) {
		.vector = regs->vect_twi,
		.enable = AVR_IO_REGBIT(regs->twcr, TWCR_TWIE),
		.raised = AVR_IO_REGBIT(regs->twcr, TWCR_TWINT),
		.raise_sticky = 1,
	};
	avr_register_vector(avr, &t->vect_twi);
	isr_watch_init(&t->isr, avr, &t->vect_twi);
	avr_irq_register_notify(&t->vect_twi.irq[AVR_INT_IRQ_RUNNING],
				twi_irq_running, t);

	io_hook_take(avr, regs->twbr, NULL, twi_write_plain, t);
	io_hook_take(avr, regs->twsr, NULL, twi_write_twsr, t);
	io_hook_take(avr, regs->twar, NULL, twi_write_plain, t);
	io_hook_take(avr, regs->twdr, NULL, twi_write_twdr, t);
	io_hook_take(avr, regs->twcr, NULL, twi_write_twcr, t);

	io_hook_register_last(avr, &t->io);
	twi_reset(&t->io);
}
