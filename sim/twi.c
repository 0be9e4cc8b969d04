/*
 * twi.c: TWI model, master mode.
 */
#include <string.h>

#include "sim_regbit.h"

#include "twi.h"

/* TWCR bits and TWSR status codes (datasheet / avr-libc util/twi.h names). */
enum {
	TWCR_TWINT = 7, TWCR_TWEA = 6, TWCR_TWSTA = 5, TWCR_TWSTO = 4,
	TWCR_TWWC = 3, TWCR_TWEN = 2, TWCR_TWIE = 0,
};
enum {
	TW_START = 0x08, TW_REP_START = 0x10,
	TW_MT_SLA_ACK = 0x18, TW_MT_SLA_NACK = 0x20,
	TW_MT_DATA_ACK = 0x28, TW_MT_DATA_NACK = 0x30,
	TW_MT_ARB_LOST = 0x38,
	TW_MR_SLA_ACK = 0x40, TW_MR_SLA_NACK = 0x48,
	TW_MR_DATA_ACK = 0x50, TW_MR_DATA_NACK = 0x58,
	TW_NO_INFO = 0xf8,
};

#define BIT(b) (1u << (b))
#define TWSR_TWPS 0x03

static inline uint8_t *twi_reg(const twi_t *t, uint16_t addr)
{
	return &t->avr->data[addr];
}

avr_cycle_count_t twi_scl_period(const twi_t *t)
{
	unsigned twps = *twi_reg(t, t->regs->twsr) & TWSR_TWPS;

	return 16 + 2 * (avr_cycle_count_t)*twi_reg(t, t->regs->twbr) * (1u << (2 * twps));
}

/* TWINT is a level: while it and TWIE are set the interrupt is requested
 * (the ISR does not clear it; see usart.c for the re-raise scheme). */
static void twi_sync(twi_t *t)
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

static void twi_done(twi_t *t, uint8_t status)
{
	t->status = status;
	t->op = TWI_OP_NONE;
	*twi_reg(t, t->regs->twcr) |= BIT(TWCR_TWINT);
	twi_sync(t);
}

static avr_cycle_count_t twi_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	twi_t *t = param;
	uint8_t *twcr = twi_reg(t, t->regs->twcr);
	uint8_t *twdr = twi_reg(t, t->regs->twdr);
	int ack;

	(void)avr;
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
			t->op = TWI_OP_START;
			return when + twi_scl_period(t);
		}
		t->op = TWI_OP_NONE;
		twi_sync(t);	/* no TWINT after a STOP */
		break;
	case TWI_OP_SLA:
		ack = twi_bus_address(t->bus, when, *twdr);
		if (*twdr & 1) {
			twi_done(t, ack ? TW_MR_SLA_ACK : TW_MR_SLA_NACK);
		} else {
			twi_done(t, ack ? TW_MT_SLA_ACK : TW_MT_SLA_NACK);
		}
		break;
	case TWI_OP_TX:
		ack = twi_bus_write(t->bus, when, *twdr);
		twi_done(t, ack ? TW_MT_DATA_ACK : TW_MT_DATA_NACK);
		break;
	case TWI_OP_RX:
		*twdr = twi_bus_read(t->bus, when, t->op_ack);
		twi_done(t, t->op_ack ? TW_MR_DATA_ACK : TW_MR_DATA_NACK);
		break;
	case TWI_OP_NONE:
		break;
	}
	return 0;
}

static void twi_begin(twi_t *t, twi_op_t op, avr_cycle_count_t periods)
{
	t->op = op;
	avr_cycle_timer_register(t->avr, periods * twi_scl_period(t), twi_timer, t);
}

/* TWINT was cleared with TWEN set: start what TWSTA/TWSTO and the state
 * ask for. */
static void twi_action(twi_t *t, uint8_t cr)
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
		/* After 48/58 only START/STOP are defined; when idle, slave
		 * mode (not modelled yet) would wait to be addressed. */
		break;
	}
}

static void twi_write_twcr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	twi_t *t = param;
	uint8_t old = avr->data[addr];
	uint8_t keep = old & (BIT(TWCR_TWINT) | BIT(TWCR_TWWC));
	uint8_t cr = (uint8_t)(v & ~(BIT(TWCR_TWINT) | BIT(TWCR_TWWC) | 0x02));
	int clear_int = !!(v & BIT(TWCR_TWINT));

	/* TWSTO stays set by hardware until its STOP is on the bus. */
	if (t->op == TWI_OP_STOP || t->op == TWI_OP_STOP_START) {
		cr |= BIT(TWCR_TWSTO);
	}
	if (clear_int) {
		keep &= (uint8_t)~BIT(TWCR_TWINT);
	}
	avr->data[addr] = (uint8_t)(keep | cr);

	if (!(v & BIT(TWCR_TWEN))) {
		/* TWI off: transfers end, the lines are released. */
		avr_cycle_timer_cancel(avr, twi_timer, t);
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
}

static void twi_write_twdr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	twi_t *t = param;
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
	twi_t *t = param;

	avr->data[addr] = (uint8_t)(t->status | (v & TWSR_TWPS));
}

static void twi_write_plain(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	(void)param;
	avr->data[addr] = v;
}

static void twi_take(avr_t *avr, uint16_t addr, avr_io_write_t w, void *param)
{
	avr_io_addr_t io = AVR_DATA_TO_IO(addr);

	avr->io[io].r.c = NULL;		/* registers live in avr->data */
	avr->io[io].r.param = NULL;
	avr->io[io].w.c = w;
	avr->io[io].w.param = param;
}

static void twi_irq_running(struct avr_irq_t *irq, uint32_t value, void *param)
{
	(void)irq;
	(void)value;
	twi_sync(param);
}

static void twi_reset(avr_io_t *io)
{
	twi_t *t = (twi_t *)io;
	avr_t *avr = t->avr;

	t->op = TWI_OP_NONE;
	t->owner = 0;
	t->status = TW_NO_INFO;
	avr->data[t->regs->twbr] = 0;
	avr->data[t->regs->twsr] = TW_NO_INFO;
	avr->data[t->regs->twar] = 0xfe;
	avr->data[t->regs->twdr] = 0xff;
	avr->data[t->regs->twcr] = 0;
	twi_sync(t);
}

void twi_init(twi_t *t, avr_t *avr, const mcu_twi_regs_t *regs, twi_bus_t *bus)
{
	memset(t, 0, sizeof(*t));
	t->avr = avr;
	t->regs = regs;
	t->bus = bus;
	t->io.kind = "orfa-twi";
	t->io.reset = twi_reset;

	t->vect_twi = (avr_int_vector_t) {
		.vector = regs->vect_twi,
		.enable = AVR_IO_REGBIT(regs->twcr, TWCR_TWIE),
		.raised = AVR_IO_REGBIT(regs->twcr, TWCR_TWINT),
		.raise_sticky = 1,
	};
	avr_register_vector(avr, &t->vect_twi);
	avr_irq_register_notify(&t->vect_twi.irq[AVR_INT_IRQ_RUNNING],
				twi_irq_running, t);

	twi_take(avr, regs->twbr, twi_write_plain, t);
	twi_take(avr, regs->twsr, twi_write_twsr, t);
	twi_take(avr, regs->twar, twi_write_plain, t);
	twi_take(avr, regs->twdr, twi_write_twdr, t);
	twi_take(avr, regs->twcr, twi_write_twcr, t);

	mcu_register_io_last(avr, &t->io);
	twi_reset(&t->io);
}
