/*
 * twi.c: TWI model, master and slave mode (twi.h).
 */
#include <inttypes.h>
#include <stddef.h>
#include <string.h>

#include "sim_regbit.h"
#include "avr_ioport.h"

#include "periph/io_hook.h"
#include "periph/sim_twi.h"
#include "periph/avr_libc_twi.h"
#include "simavr16/interrupt.h"

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
		simavr16_withdraw_interrupt(t->avr, v);
	}
}

static void twi_done(sim_twi_t *t, uint8_t status)
{
	t->status = status;
	t->op = TWI_OP_NONE;
	*twi_reg(t, t->regs->twcr) |= BIT(TWCR_TWINT);
	twi_sync(t);
}

/* --- master mode -----------------------------------------------------------
 *
 * An operation puts its bits on the lines one edge at a time, each edge a
 * step of a cycle timer stamped with its exact cycle (simavr may call the
 * timer a few cycles later; the lines get the exact one). With P the SCL
 * period (16 + 2*TWBR*4^TWPS) and B the cycle a bit's SCL low began:
 *
 *   a bit: SDA set at B + P/4, SCL let go at B + P/2; from the cycle H SCL is
 *   seen high (a device may hold it longer: clock synchronisation) the bit
 *   is sampled, and SCL pulled low at H + P/2, which begins the next bit;
 *   a byte is 8 bits and the acknowledge: 9P, TWINT at the 9th falling edge;
 *   START on a free bus: SDA low at B + P/2, SCL low at B + P;
 *   repeated START: SDA let go at B + P/4, SCL at B + P/2, SDA low at
 *   H + P/4 (SCL high), SCL low at H + P/2;
 *   STOP: SDA low at B + P/4, SCL let go at B + P/2, SDA let go at H + P/2.
 *
 * An operation begins when the firmware asks (TWINT cleared, TWSTA) and
 * nothing but this master holds SCL: a slave's stretch after an
 * acknowledge delays the whole operation (it then takes its full time
 * from the release); a START waits for a free bus (SDA and SCL high).
 */

enum { M_LOW = 1, M_RISE, M_MID, M_FALL, M_GLITCH };

static void twi_drive(sim_twi_t *t, int sda_low, int scl_low, avr_cycle_count_t cycle)
{
	twi_bus_drive(t->bus, &t->drv, sda_low, scl_low, cycle);
}

static avr_cycle_count_t twi_timer(avr_t *avr, avr_cycle_count_t when, void *param);

/* The next STEP at CYCLE. */
static void twi_at(sim_twi_t *t, avr_cycle_count_t cycle, uint8_t step)
{
	avr_cycle_count_t now = t->avr->cycle;

	t->step = step;
	t->step_at = cycle;
	avr_cycle_timer_register(t->avr, cycle > now ? cycle - now : 1, twi_timer, t);
}

static void twi_wait(sim_twi_t *t, twi_wait_t what, avr_cycle_count_t now)
{
	t->waiting = (uint8_t)what;
	twi_bus_wait(t->bus, &t->master, &t->drv, what, now);
}

/* Whether the master pulls SDA low in the low half of the bit under way. */
static int twi_low_sda(const sim_twi_t *t)
{
	switch (t->op) {
	case TWI_OP_START:
		return 0;
	case TWI_OP_STOP:
	case TWI_OP_STOP_START:
		return 1;
	case TWI_OP_RX:
		return t->bit == 8 && t->op_ack;
	default:
		/* after a lost bit the master sends nothing (1s) */
		return !t->lost && t->bit < 8 && !(t->byte & (0x80 >> t->bit));
	}
}

/* The rival (`i2c arb`, twi_fault.h) acts in the bit under way. */
static int twi_rival_bit(const sim_twi_t *t)
{
	return t->fault == TWI_FAULT_ARB && t->bit == t->fault_bit;
}

/* A bit's SCL low half began at cycle B: SDA changes a quarter period on
 * (a step only when it changes: an edge-less step costs as much), SCL is
 * let go half a period on. */
static void twi_low_half(sim_twi_t *t, avr_cycle_count_t b)
{
	t->bit_at = b;
	if (twi_low_sda(t) != t->drv.sda_low || twi_rival_bit(t)) {
		twi_at(t, b + t->half / 2, M_LOW);
	} else {
		twi_at(t, b + t->half, M_RISE);
	}
}

/* The operation begins on the lines at cycle B. */
static void twi_go(sim_twi_t *t, avr_cycle_count_t b)
{
	t->half = sim_twi_scl_period(t) / 2;
	t->bit_at = b;
	t->bit = 0;
	if (t->op == TWI_OP_START && !t->owner) {
		/* SCL is high: SDA falls half a period on, SCL half a period later */
		t->fall_at = b + 2 * t->half;
		twi_at(t, b + t->half, M_MID);
		return;
	}
	if (t->op == TWI_OP_SLA || t->op == TWI_OP_TX) {
		t->byte = *twi_reg(t, t->regs->twdr);
	}
	if (t->op == TWI_OP_SLA || t->op == TWI_OP_TX || t->op == TWI_OP_RX) {
		unsigned bit = 0;

		t->lost = 0;
		t->fault = (uint8_t)twi_fault_here(&t->bus->fault, &bit);
		t->fault_bit = (uint8_t)bit;
		t->bus->in_byte = &t->master;
		twi_bus_byte(t->bus, b, b + 18 * t->half);
	}
	twi_low_half(t, b);
}

/* The firmware asked for the operation at cycle NOW: begin when the bus
 * lets it. */
static void twi_begin(sim_twi_t *t, sim_twi_op_t op)
{
	twi_bus_t *bus = t->bus;
	avr_cycle_count_t now = t->avr->cycle;

	t->op = op;
	if (op == TWI_OP_START && !t->owner) {
		if (!bus->scl || !bus->sda) {
			if (!bus->scl_ext || bus->sda) {
				trace_event(bus->trace, now, "twi wait SCL");
			} else {
				trace_event(bus->trace, now, "twi wait SDA");
			}
			twi_wait(t, TWI_WAIT_BUS_FREE, now);
			return;
		}
	} else if (twi_bus_scl_held(bus, &t->drv)) {
		if (!bus->scl_ext) {
			trace_event(bus->trace, now, "twi wait SCL");
		}
		twi_wait(t, TWI_WAIT_SCL_FREE, now);
		return;
	}
	/* A slave that ran ahead inside the lock-step quantum may have let
	 * SCL go after NOW: the operation begins at its release. */
	if (t->owner && bus->scl_free_at > now) {
		trace_event(bus->trace, bus->scl_free_at, "twi stretch %02X %" PRIu64,
			    bus->scl_free_by, bus->scl_free_at - now);
		now = bus->scl_free_at;
	}
	twi_go(t, now);
}

/* SCL was seen high from cycle H. */
static void twi_high(sim_twi_t *t, avr_cycle_count_t h)
{
	int sda = t->bus->sda;

	if ((t->fault == TWI_FAULT_START || t->fault == TWI_FAULT_STOP) &&
	    t->bit == t->fault_bit) {
		/* a glitch armed for this bit: in SCL's high half */
		twi_at(t, h + t->half / 2, M_GLITCH);
		return;
	}
	switch (t->op) {
	case TWI_OP_START:
		t->fall_at = h + t->half;
		twi_at(t, h + t->half / 2, M_MID);
		return;
	case TWI_OP_STOP:
	case TWI_OP_STOP_START:
		twi_at(t, h + t->half, M_MID);
		return;
	case TWI_OP_RX:
		if (t->bit < 8) {
			t->byte = (uint8_t)(t->byte << 1 | sda);
		} else if (!t->op_ack && !sda) {
			t->lost = 1;	/* its NACK read low: arbitration lost */
		}
		break;
	default:
		if (t->bit == 8) {
			t->line_ack = (uint8_t)!sda;
		} else {
			t->line_byte = (uint8_t)(t->line_byte << 1 | sda);
			if (!t->drv.sda_low && !sda) {
				/* a bit sent high reads low: arbitration lost;
				 * SDA let go for the rest of the byte, which it
				 * clocks to its end */
				t->lost = 1;
			}
		}
		break;
	}
	twi_at(t, h + t->half, M_FALL);
}

/* The rival (`i2c arb`, twi_fault.h) pulls SDA low for the bit that begins
 * at WHEN (ON), or lets it go when it ends. */
static void twi_rival(sim_twi_t *t, int on, avr_cycle_count_t when)
{
	if (twi_rival_bit(t)) {
		twi_bus_drive(t->bus, &t->bus->rival_drv, on, 0, when);
	}
}

/* The master lost arbitration in the byte that ended at WHEN (SCL fell
 * after its acknowledge): it is not the master any more. Addressed by the
 * address the devices read (its TWAR, TWEA set: its own front acknowledged
 * it, twi_dev_start) it is a slave from here, 0x68 (written to), 0x78 (the
 * general call, with TWGCE) or 0xB0 (read from); else 0x38, holding SCL
 * until TWINT is cleared. */
static void twi_arb_lost(sim_twi_t *t, avr_cycle_count_t when)
{
	t->owner = 0;
	t->bus->clocked = 0;
	if (t->addressed) {
		trace_event(t->bus->trace, when, "twi arb-lost %02X", t->sl_addr);
		twi_drive(t, 0, 0, when);	/* its slave side holds SCL */
		t->op = TWI_OP_NONE;
		if (t->addressed == TWI_SLAVE_TX) {
			t->status = TW_ST_ARB_LOST_SLA_ACK;
		} else {
			t->status = t->sl_gcall ? TW_SR_ARB_LOST_GCALL_ACK : TW_SR_ARB_LOST_SLA_ACK;
		}
		t->sl_status = t->status;
		twi_sync(t);
		return;
	}
	trace_event(t->bus->trace, when, "twi arb-lost");
	twi_drive(t, 0, 1, when);
	twi_done(t, TW_MT_ARB_LOST);
}

/* This master's byte is over (done, cut): the lines' conditions are no
 * longer its bus error. */
static void twi_byte_over(sim_twi_t *t)
{
	if (t->bus->in_byte == &t->master) {
		t->bus->in_byte = NULL;
	}
}

/* A bus error at WHEN in the byte under way: the TWI lets the lines go
 * and sets TWINT with 0x00 (TWSTO or TWEN off recovers). */
static void twi_bus_error(sim_twi_t *t, avr_cycle_count_t when)
{
	trace_event(t->bus->trace, when, "twi bus-error");
	t->owner = 0;
	t->bus->clocked = 0;
	twi_drive(t, 0, 0, when);
	twi_done(t, TW_BUS_ERROR);
}

/* A glitch in the bit under way, at WHEN: the condition to every device,
 * and this TWI's bus error. */
static void twi_glitch(sim_twi_t *t, avr_cycle_count_t when)
{
	twi_byte_over(t);
	twi_bus_glitch(t->bus, when, t->fault == TWI_FAULT_START);
	twi_bus_error(t, when);
}

static void twi_master_resume(twi_bus_master_t *m, uint64_t cycle)
{
	sim_twi_t *t = (sim_twi_t *)((char *)m - offsetof(sim_twi_t, master));
	twi_wait_t what = (twi_wait_t)t->waiting;

	t->waiting = TWI_WAIT_NONE;
	if (t->op == TWI_OP_NONE) {
		return;
	}
	if (what == TWI_WAIT_SCL_HIGH) {
		twi_high(t, cycle);
	} else {
		twi_go(t, cycle);
	}
}

/* The byte and its acknowledge are done at cycle WHEN (SCL fell). */
static void twi_byte_done(sim_twi_t *t, avr_cycle_count_t when)
{
	uint8_t *twdr = twi_reg(t, t->regs->twdr);
	uint8_t status;

	twi_byte_over(t);
	switch (t->op) {
	case TWI_OP_SLA:
		twi_bus_note_addr(t->bus, when, t->line_byte, t->line_ack);
		if (t->byte & 1) {
			status = t->line_ack ? TW_MR_SLA_ACK : TW_MR_SLA_NACK;
		} else {
			status = t->line_ack ? TW_MT_SLA_ACK : TW_MT_SLA_NACK;
		}
		break;
	case TWI_OP_TX:
		twi_bus_note_write(t->bus, when, t->line_byte, t->line_ack);
		status = t->line_ack ? TW_MT_DATA_ACK : TW_MT_DATA_NACK;
		break;
	default:
		/* its acknowledge given, the master lets SDA go */
		twi_drive(t, 0, 1, when);
		*twdr = t->byte;
		twi_bus_note_read(t->bus, when, t->byte, t->op_ack || t->lost);
		status = t->op_ack ? TW_MR_DATA_ACK : TW_MR_DATA_NACK;
		break;
	}
	if (t->lost) {
		twi_arb_lost(t, when);
	} else {
		twi_done(t, status);
	}
}

/* The STOP is on the lines at cycle WHEN (SDA let go with SCL high). */
static void twi_stop_done(sim_twi_t *t, avr_cycle_count_t when)
{
	twi_bus_note_stop(t->bus, when);
	t->owner = 0;
	*twi_reg(t, t->regs->twcr) &= (uint8_t)~BIT(TWCR_TWSTO);
	t->status = TW_NO_INFO;
	if (t->op == TWI_OP_STOP_START) {
		t->op = TWI_OP_START;
		twi_begin(t, TWI_OP_START);
		return;
	}
	t->op = TWI_OP_NONE;
	twi_sync(t);	/* no TWINT after a STOP */
}

static avr_cycle_count_t twi_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	sim_twi_t *t = param;

	(void)avr;
	/* The lines get the exact cycle, not the one simavr called us at. */
	when = t->step_at;
	switch (t->step) {
	case M_LOW:
		twi_drive(t, twi_low_sda(t), 1, when);
		twi_rival(t, 1, when);
		twi_at(t, t->bit_at + t->half, M_RISE);
		break;
	case M_RISE:
		twi_drive(t, t->drv.sda_low, 0, when);
		if (t->bus->scl) {
			twi_high(t, when);
		} else {
			if (!t->bus->scl_ext) {
				trace_event(t->bus->trace, when, "twi wait SCL");
			}
			twi_wait(t, TWI_WAIT_SCL_HIGH, when);
		}
		break;
	case M_MID:
		if (t->op == TWI_OP_START) {
			twi_drive(t, 1, 0, when);
			twi_at(t, t->fall_at, M_FALL);
		} else {
			twi_drive(t, 0, 0, when);
			twi_stop_done(t, when);
		}
		break;
	case M_FALL:
		twi_drive(t, t->drv.sda_low, 1, when);
		twi_rival(t, 0, when);
		if (t->op == TWI_OP_START) {
			twi_bus_note_start(t->bus, when);
			twi_done(t, t->owner ? TW_REP_START : TW_START);
			t->owner = 1;
		} else if (++t->bit < 9) {
			twi_low_half(t, when);
		} else {
			twi_byte_done(t, when);
		}
		break;
	case M_GLITCH:
		twi_glitch(t, when);
		break;
	default:
		break;
	}
	return 0;
}

/* The master stops at WHEN and lets the lines go (TWI off, reset, a bus
 * error from the lines): SDA first, so with SCL low it is no STOP. With
 * SCL high in a byte's first bit, SDA rising would be a STOP on silicon,
 * and a slave would take the frame cut there as whole; the model makes any
 * release inside a byte a bus error to the devices instead
 * (docs/simulator.md, "The lines"). */
static void twi_master_off(sim_twi_t *t, avr_cycle_count_t when)
{
	int in_byte = t->op == TWI_OP_SLA || t->op == TWI_OP_TX || t->op == TWI_OP_RX;

	avr_cycle_timer_cancel(t->avr, twi_timer, t);
	twi_bus_cancel(t->bus, &t->master);
	t->waiting = TWI_WAIT_NONE;
	twi_byte_over(t);
	t->bus->abort = in_byte;
	twi_drive(t, 0, t->drv.scl_low, when);
	twi_drive(t, 0, 0, when);
	/* the rival's bit ends with the clock that made it */
	twi_bus_drive(t->bus, &t->bus->rival_drv, 0, 0, when);
	t->bus->abort = 0;
	if (t->owner) {
		t->bus->clocked = 0;
	}
	t->op = TWI_OP_NONE;
	t->owner = 0;
}

/* A START or STOP on the lines at CYCLE while this master clocks a byte
 * (another driver moved SDA with SCL high): its bus error, as the
 * datasheet's TWI detects it. The bus calls this while it tells that edge,
 * so the lines let go here are told after it (the devices have seen the
 * condition itself). */
static void twi_master_condition(twi_bus_master_t *m, uint64_t cycle)
{
	sim_twi_t *t = (sim_twi_t *)((char *)m - offsetof(sim_twi_t, master));

	twi_master_off(t, cycle);
	twi_bus_error(t, cycle);
}

/* --- slave mode -----------------------------------------------------------
 *
 * The TWI as a device behind the shared bit-level front (i2c_phy.c): it
 * decides its acknowledges at the 8th falling edge of a byte, and at the
 * end of the acknowledge bit raises TWINT and holds SCL until the firmware
 * clears it. */

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
 * then with STATUS (and DATA in TWDR). This board may be behind the master
 * inside the lock-step quantum: then the rise waits for its cycle. */
static void twi_slave_deliver(sim_twi_t *t, uint8_t status, int has_data, uint8_t data)
{
	uint64_t at = t->bus->cycle;

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

/* TWI off or reset: forget the transfer, let the lines go. */
static void twi_slave_abandon(sim_twi_t *t)
{
	if (t->sl_pending) {
		avr_cycle_timer_cancel(t->avr, twi_slave_timer, t);
		t->sl_pending = 0;
	}
	t->addressed = 0;
	twi_bus_release(t->bus, &t->dev, t->avr->cycle, t->sl_addr);
	twi_bus_forget(t->bus, &t->dev, t->avr->cycle);
}

/* TWI off or reset: the master stops, the slave side forgets its transfer. */
static void twi_off(sim_twi_t *t)
{
	twi_master_off(t, t->avr->cycle);
	twi_slave_abandon(t);
	t->status = TW_NO_INFO;
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

	/* the general call: address 0, a write, with TWGCE (TWAR bit 0) */
	int gcall = addr8 == 0x00 && (twar & 1);

	/* A master never answers its own address (but one that lost
	 * arbitration in it may be the winner's slave); a slave answers only
	 * while enabled with TWEA and idle (the bus waits for a TWINT it
	 * holds). */
	if (((t->owner || t->op != TWI_OP_NONE) && !t->lost) || t->sl_pending || dev->hold ||
	    !(cr & BIT(TWCR_TWEN)) || !(cr & BIT(TWCR_TWEA)) || (cr & BIT(TWCR_TWINT)) ||
	    ((addr8 & 0xfe) != (twar & 0xfe) && !gcall)) {
		return 0;
	}
	t->sl_gcall = gcall;
	t->sl_addr = addr8 & 0xfe;
	t->addressed = addr8 & 1 ? TWI_SLAVE_TX : TWI_SLAVE_RX;
	t->sl_got_addr = 1;
	return 1;
}

static int twi_dev_write(twi_dev_t *dev, uint8_t byte)
{
	sim_twi_t *t = twi_of_dev(dev);

	if (t->addressed != TWI_SLAVE_RX) {
		return 0;
	}
	t->sl_rx = byte;
	return t->sl_ea;
}

static uint8_t twi_dev_read(twi_dev_t *dev)
{
	sim_twi_t *t = twi_of_dev(dev);

	return t->addressed == TWI_SLAVE_TX ? t->sl_tx : 0xff;	/* else the pull-ups */
}

static int twi_dev_ack_end(twi_dev_t *dev, int ack)
{
	sim_twi_t *t = twi_of_dev(dev);
	uint8_t status;

	if (t->sl_got_addr) {
		t->sl_got_addr = 0;
		if (t->addressed == TWI_SLAVE_TX) {
			status = TW_ST_SLA_ACK;
		} else {
			status = t->sl_gcall ? TW_SR_GCALL_ACK : TW_SR_SLA_ACK;
		}
		twi_slave_deliver(t, status, 0, 0);
		return 1;
	}
	if (t->addressed == TWI_SLAVE_RX) {
		if (!ack) {
			t->addressed = 0;	/* NACKed: not addressed until the next START */
		}
		if (t->sl_gcall) {
			status = ack ? TW_SR_GCALL_DATA_ACK : TW_SR_GCALL_DATA_NACK;
		} else {
			status = ack ? TW_SR_DATA_ACK : TW_SR_DATA_NACK;
		}
		twi_slave_deliver(t, status, 1, t->sl_rx);
		return 1;
	}
	if (t->addressed != TWI_SLAVE_TX) {
		return 0;
	}
	if (!ack) {
		status = TW_ST_DATA_NACK;
	} else if (t->sl_ea) {
		status = TW_ST_DATA_ACK;
	} else {
		status = TW_ST_LAST_DATA;
	}
	if (status != TW_ST_DATA_ACK) {
		t->addressed = 0;
	}
	twi_slave_deliver(t, status, 0, 0);
	return 1;
}

/* STOP, or a repeated START, ends a transfer this slave takes part in. */
static void twi_dev_end(twi_dev_t *dev)
{
	sim_twi_t *t = twi_of_dev(dev);

	t->sl_got_addr = 0;
	if (t->addressed == TWI_SLAVE_RX) {
		t->addressed = 0;
		twi_slave_deliver(t, TW_SR_STOP, 0, 0);
		twi_bus_hold(t->bus, dev, TWI_HOLD_ADDR);
	} else {
		/* the datasheet gives a transmitter no code for it */
		t->addressed = 0;
	}
}

/* A START or STOP in the middle of a byte this slave takes part in: TWINT
 * with 0x00; the firmware recovers with TWSTO (twi_action). SCL is not
 * held. */
static void twi_dev_bus_error(twi_dev_t *dev)
{
	sim_twi_t *t = twi_of_dev(dev);

	if (!t->addressed) {
		return;
	}
	trace_event(t->bus->trace, t->bus->cycle, "twi bus-error %02X", t->sl_addr);
	t->addressed = 0;
	t->sl_got_addr = 0;
	twi_slave_deliver(t, TW_BUS_ERROR, 0, 0);
}

static const twi_dev_ops_t twi_dev_ops = {
	.start = twi_dev_start,
	.write = twi_dev_write,
	.read = twi_dev_read,
	.stop = twi_dev_end,
	.bus_start = twi_dev_end,
	.ack_end = twi_dev_ack_end,
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
	twi_bus_drive(t->bus, &t->pins, sda_low, scl_low, t->avr->cycle);
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

	if (t->status == TW_MT_ARB_LOST) {
		/* the bus released, not addressed slave mode (or a START
		 * once the bus is free) */
		twi_drive(t, 0, 0, t->avr->cycle);
	}
	if (sto) {
		if (t->owner) {
			twi_begin(t, sta ? TWI_OP_STOP_START : TWI_OP_STOP);
			return;
		}
		/* Not the master: TWSTO only recovers from a bus error. */
		*twi_reg(t, t->regs->twcr) &= (uint8_t)~BIT(TWCR_TWSTO);
		t->status = TW_NO_INFO;
	}
	if (sta) {
		twi_begin(t, TWI_OP_START);
		return;
	}
	switch (t->status) {
	case TW_START:
	case TW_REP_START:
		twi_begin(t, TWI_OP_SLA);
		break;
	case TW_MT_SLA_ACK:
	case TW_MT_SLA_NACK:
	case TW_MT_DATA_ACK:
	case TW_MT_DATA_NACK:
		twi_begin(t, TWI_OP_TX);
		break;
	case TW_MR_SLA_ACK:
	case TW_MR_DATA_ACK:
		t->op_ack = !!(cr & BIT(TWCR_TWEA));
		twi_begin(t, TWI_OP_RX);
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
		twi_off(t);
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
	twi_off(t);
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
	t->master.condition = twi_master_condition;
	t->dev.ops = &twi_dev_ops;
	t->dev.name = "avr-twi";
	twi_bus_attach(bus, &t->dev);
	twi_bus_attach_drv(bus, &t->drv, 0);
	twi_bus_attach_drv(bus, &t->pins, 1);

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
