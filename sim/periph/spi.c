/*
 * spi.c: SPI master model and device bus.
 */
#include <string.h>

#include "sim_regbit.h"

#include "periph/io_hook.h"
#include "periph/sim_mcu.h"
#include "periph/spi.h"
#include "simavr16/interrupt.h"

enum {
	SPCR_SPIE = 7, SPCR_SPE = 6, SPCR_DORD = 5, SPCR_MSTR = 4,
	SPCR_CPOL = 3, SPCR_CPHA = 2, SPCR_SPR1 = 1, SPCR_SPR0 = 0,
	SPSR_SPIF = 7, SPSR_WCOL = 6, SPSR_SPI2X = 0,
};

#define BIT(b) (1u << (b))

static inline uint8_t spi_spcr(const spi_t *s)
{
	return s->avr->data[s->spcr];
}

unsigned spi_byte_cycles(const spi_t *s)
{
	static const unsigned div[4] = { 4, 16, 64, 128 };
	unsigned period = div[spi_spcr(s) & 3];

	if (s->spsr_v & BIT(SPSR_SPI2X)) {
		period /= 2;
	}
	return 8 * period;
}

/* SPIF is a flag the ISR's entry clears; the vector is requested while it
 * and SPIE are set (same scheme as usart.c). */
static void spi_sync(spi_t *s)
{
	avr_int_vector_t *v = &s->vect;

	s->avr->data[s->spsr] = s->spsr_v;
	if (s->spsr_v & BIT(SPSR_SPIF)) {
		if (!v->pending && (spi_spcr(s) & BIT(SPCR_SPIE))) {
			avr_raise_interrupt(s->avr, v);
		}
	} else if (v->pending) {
		simavr16_withdraw_interrupt(s->avr, v);
	}
}

/* --- devices ------------------------------------------------------------- */

static void spi_byte_select(spi_dev_t *d, uint64_t cycle)
{
	d->rx = 0;
	d->rx_n = 0;
	d->tx = 0xff;
	d->tx_next = 0xff;
	d->tx_n = 0;
	if (d->reset_state) {
		d->reset_state(d, cycle);
	}
}

static void spi_byte_deselect(spi_dev_t *d, uint64_t cycle)
{
	if (d->end) {
		d->end(d, cycle);
	}
}

static void spi_byte_in(spi_dev_t *d, int bit, uint64_t cycle)
{
	if (d->lsb_first) {
		d->rx |= (uint8_t)(bit << d->rx_n);
	} else {
		d->rx = (uint8_t)((d->rx << 1) | bit);
	}
	if (++d->rx_n == 8) {
		d->tx_next = d->byte(d, d->rx, cycle);
		d->rx = 0;
		d->rx_n = 0;
	}
}

static int spi_byte_out(spi_dev_t *d)
{
	if (d->tx_n == 8) {
		d->tx = d->tx_next;
		d->tx_next = 0xff;
		d->tx_n = 0;
	}
	int k = d->tx_n++;

	return d->lsb_first ? (d->tx >> k) & 1 : (d->tx >> (7 - k)) & 1;
}

void spi_dev_byte_init(spi_dev_t *d)
{
	d->select = spi_byte_select;
	d->deselect = spi_byte_deselect;
	d->in_bit = spi_byte_in;
	d->next_out = spi_byte_out;
}

/* The device that drives MISO: the first one selected (NULL: none). */
static spi_dev_t *spi_selected(const spi_t *s)
{
	for (int i = 0; i < s->ndev; i++) {
		if (s->dev[i]->selected) {
			return s->dev[i];
		}
	}
	return NULL;
}

static int spi_master_on(const spi_t *s)
{
	uint8_t cr = spi_spcr(s);

	return (cr & BIT(SPCR_SPE)) && (cr & BIT(SPCR_MSTR));
}

/* Show on the MISO pin what drives it at CYCLE: the selected device's bit;
 * with none, 1 (what the master reads) while the master is on, else the
 * port's own. A byte on the wire shows its edges when it ends. */
static void spi_miso_show(spi_t *s, uint64_t cycle)
{
	spi_dev_t *d;

	if (!s->drive || s->busy) {
		return;
	}
	d = spi_selected(s);
	s->miso_level = d ? d->out : 1;
	s->drive(s->drive_param, SPI_PIN_MISO, d || spi_master_on(s), s->miso_level, cycle);
}

static void spi_cs_changed(void *param, signal_t *sig, uint64_t cycle, int level)
{
	spi_dev_t *d = param;

	(void)sig;
	if (!level && !d->selected) {
		d->selected = 1;
		d->txn++;
		d->select(d, cycle);
		/* CPHA 0: the first bit is on MISO as soon as CS falls. */
		d->out = (d->mode & 1) ? 1 : d->next_out(d);
	} else if (level && d->selected) {
		d->selected = 0;
		d->out = 1;
		d->deselect(d, cycle);
	}
	if (d->bus) {
		spi_miso_show(d->bus, cycle);
	}
}

int spi_attach(spi_t *s, spi_dev_t *d, signal_t *cs)
{
	if (s->ndev == SPI_MAX_DEVICES) {
		return -1;
	}
	d->cs = cs;
	d->bus = s;
	d->selected = 0;
	d->out = 1;
	s->dev[s->ndev++] = d;
	signal_listen(cs, spi_cs_changed, d);
	if (!cs->level) {
		spi_cs_changed(d, cs, 0, 0);
	}
	return 0;
}

/* --- the byte on the wire ------------------------------------------------ */

static void spi_edge_note(spi_t *s, uint64_t cycle, int pin, int level)
{
	if (s->nedges < (int)(sizeof(s->edge_cycle) / sizeof(s->edge_cycle[0]))) {
		s->edge_cycle[s->nedges] = cycle;
		s->edge_pin[s->nedges] = (uint8_t)pin;
		s->edge_level[s->nedges] = (uint8_t)level;
		s->nedges++;
	}
}

/* MISO as device D (NULL: none, the line reads 1) drives it at WHEN, noted
 * among the byte's edges when it changes. */
static void spi_miso_note(spi_t *s, const spi_dev_t *d, uint64_t when)
{
	int level = d ? d->out : 1;

	if (level != s->miso_level) {
		s->miso_level = level;
		spi_edge_note(s, when, SPI_PIN_MISO, level);
	}
}

/* Clock one byte through the selected devices, edge by edge. At each edge
 * everyone who samples sees the levels from before it; then the shifters
 * move. */
static uint8_t spi_clock_byte(spi_t *s, uint8_t tx, uint64_t t0, unsigned half)
{
	uint8_t cr = spi_spcr(s);
	int cpol = !!(cr & BIT(SPCR_CPOL)), cpha = !!(cr & BIT(SPCR_CPHA));
	int lsb = !!(cr & BIT(SPCR_DORD));
	int sck = cpol, sampled = 0;
	uint8_t rx = 0;
	spi_dev_t *sel[SPI_MAX_DEVICES];
	int nsel = 0;

	for (int i = 0; i < s->ndev; i++) {
		if (s->dev[i]->selected) {
			sel[nsel++] = s->dev[i];
		}
	}
	s->nedges = 0;
	spi_miso_note(s, nsel ? sel[0] : NULL, t0);
#define TXBIT(k) (lsb ? (tx >> (k)) & 1 : (tx >> (7 - (k))) & 1)
	if (!cpha && s->mosi_level != TXBIT(0)) {
		s->mosi_level = TXBIT(0);
		spi_edge_note(s, t0, 1, s->mosi_level);
	}
	for (int e = 0; e < 16; e++) {
		int leading = !(e & 1);
		uint64_t when = t0 + (uint64_t)(e + 1) * half;
		int master_samples = leading == !cpha;
		int miso = nsel ? sel[0]->out : 1;
		int mosi = s->mosi_level;

		sck = !sck;
		spi_edge_note(s, when, 0, sck);
		if (master_samples) {
			int b = miso;

			rx = lsb ? (uint8_t)(rx | (b << sampled)) : (uint8_t)((rx << 1) | b);
			sampled++;
		}
		for (int i = 0; i < nsel; i++) {
			spi_dev_t *d = sel[i];
			int samples_rising = ((d->mode >> 1) ^ d->mode) & 1 ? 0 : 1;

			if (sck == samples_rising) {
				d->in_bit(d, mosi, t0);
			}
		}
		if (!master_samples) {
			/* CPHA 0: trailing edge k puts bit k+1 out; CPHA 1:
			 * leading edge k puts bit k out. */
			int k = cpha ? e / 2 : e / 2 + 1;

			if (k < 8 && s->mosi_level != TXBIT(k)) {
				s->mosi_level = TXBIT(k);
				spi_edge_note(s, when, 1, s->mosi_level);
			}
		}
		for (int i = 0; i < nsel; i++) {
			spi_dev_t *d = sel[i];
			int samples_rising = ((d->mode >> 1) ^ d->mode) & 1 ? 0 : 1;

			if (sck != samples_rising) {
				d->out = d->next_out(d);
			}
		}
		spi_miso_note(s, nsel ? sel[0] : NULL, when);
	}
#undef TXBIT
	s->pending_cs = nsel ? sel[0]->cs->name : "-";
	s->pending_txn = nsel ? sel[0]->txn : 0;
	return rx;
}

static avr_cycle_count_t spi_done(avr_t *avr, avr_cycle_count_t when, void *param)
{
	spi_t *s = param;

	(void)avr;
	s->busy = 0;
	s->rx = s->pending_rx;
	s->spsr_v |= BIT(SPSR_SPIF);
	for (int i = 0; i < s->nedges; i++) {
		if (s->drive) {
			s->drive(s->drive_param, s->edge_pin[i], 1, s->edge_level[i],
				 s->edge_cycle[i]);
		}
	}
	s->nedges = 0;
	spi_miso_show(s, when);
	trace_event(s->trace, when, "spi %s %02X %02X", s->pending_cs, s->tx, s->rx);
	if (s->log_len == SPI_LOG) {
		s->log_head = (s->log_head + 1) % SPI_LOG;
		s->log_len--;
	}
	s->log[(s->log_head + s->log_len) % SPI_LOG] = (spi_log_t) {
		.cycle = when, .cs = s->pending_cs, .txn = s->pending_txn,
		.mosi = s->tx, .miso = s->rx,
	};
	s->log_len++;
	s->bytes++;
	s->activity++;
	spi_sync(s);
	return 0;
}

int spi_log_pop(spi_t *s, spi_log_t *out)
{
	if (!s->log_len) {
		return 0;
	}
	*out = s->log[s->log_head];
	s->log_head = (s->log_head + 1) % SPI_LOG;
	s->log_len--;
	return 1;
}

/* --- registers ----------------------------------------------------------- */

static void spi_clear_on_access(spi_t *s)
{
	if (s->clear_armed) {
		s->spsr_v &= (uint8_t)~(BIT(SPSR_SPIF) | BIT(SPSR_WCOL));
		s->clear_armed = 0;
		spi_sync(s);
	}
}

static uint8_t spi_read_spdr(avr_t *avr, avr_io_addr_t addr, void *param)
{
	spi_t *s = param;

	(void)addr;
	spi_clear_on_access(s);
	avr->data[s->spdr] = s->rx;
	return s->rx;
}

static void spi_pins(spi_t *s)
{
	uint8_t cr = spi_spcr(s);
	int on = spi_master_on(s);

	if (s->drive && !s->busy) {
		s->drive(s->drive_param, SPI_PIN_SCK, on, !!(cr & BIT(SPCR_CPOL)), s->avr->cycle);
		s->drive(s->drive_param, SPI_PIN_MOSI, on, s->mosi_level, s->avr->cycle);
		spi_miso_show(s, s->avr->cycle);
	}
}

static void spi_write_spdr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	spi_t *s = param;

	(void)addr;
	spi_clear_on_access(s);
	if (!spi_master_on(s)) {
		s->rx = v;		/* slave mode is not modelled */
		return;
	}
	if (s->busy) {
		s->spsr_v |= BIT(SPSR_WCOL);
		spi_sync(s);
		return;
	}
	unsigned cycles = spi_byte_cycles(s);

	s->busy = 1;
	s->tx = v;
	s->t0 = avr->cycle;
	s->t_end = avr->cycle + cycles;
	s->pending_rx = spi_clock_byte(s, v, avr->cycle, cycles / 16);
	s->activity++;
	avr_cycle_timer_register(avr, cycles, spi_done, s);
}

static uint8_t spi_read_spsr(avr_t *avr, avr_io_addr_t addr, void *param)
{
	spi_t *s = param;

	(void)addr;
	if (s->spsr_v & (BIT(SPSR_SPIF) | BIT(SPSR_WCOL))) {
		s->clear_armed = 1;
	}
	avr->data[s->spsr] = s->spsr_v;
	return s->spsr_v;
}

static void spi_write_spsr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	spi_t *s = param;

	(void)avr;
	(void)addr;
	s->spsr_v = (uint8_t)((s->spsr_v & ~BIT(SPSR_SPI2X)) | (v & BIT(SPSR_SPI2X)));
	spi_sync(s);
}

static void spi_write_spcr(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	spi_t *s = param;

	(void)addr;
	avr->data[s->spcr] = v;
	if (!(v & BIT(SPCR_SPE)) && s->busy) {
		/* SPI off: the byte on the wire is abandoned */
		avr_cycle_timer_cancel(avr, spi_done, s);
		s->busy = 0;
		s->nedges = 0;
	}
	spi_pins(s);
	spi_sync(s);
}

static void spi_irq_running(struct avr_irq_t *irq, uint32_t value, void *param)
{
	spi_t *s = param;

	(void)irq;
	if (value) {
		s->spsr_v &= (uint8_t)~BIT(SPSR_SPIF);
	}
	spi_sync(s);
}

static void spi_reset(avr_io_t *io)
{
	spi_t *s = (spi_t *)io;
	avr_t *avr = s->avr;

	s->busy = 0;
	s->nedges = 0;
	s->spsr_v = 0;
	s->rx = 0;
	s->clear_armed = 0;
	s->mosi_level = 0;
	avr->data[s->spcr] = 0;
	avr->data[s->spdr] = 0;
	spi_pins(s);
	spi_sync(s);
}

void spi_init(spi_t *s, avr_t *avr, uint16_t spcr, uint16_t spsr, uint16_t spdr,
	      uint8_t vect, trace_t *trace, spi_drive_t drive, void *param)
{
	memset(s, 0, sizeof(*s));
	s->avr = avr;
	s->spcr = spcr;
	s->spsr = spsr;
	s->spdr = spdr;
	s->trace = trace;
	s->drive = drive;
	s->drive_param = param;
	s->io.kind = "orfa-spi";
	s->io.reset = spi_reset;
	s->vect = (avr_int_vector_t) {
		.vector = vect,
		.enable = AVR_IO_REGBIT(spcr, SPCR_SPIE),
		.raised = AVR_IO_REGBIT(spsr, SPSR_SPIF),
		.raise_sticky = 1,
	};
	avr_register_vector(avr, &s->vect);
	avr_irq_register_notify(&s->vect.irq[AVR_INT_IRQ_RUNNING], spi_irq_running, s);
	io_hook_take(avr, spcr, NULL, spi_write_spcr, s);
	io_hook_take(avr, spsr, spi_read_spsr, spi_write_spsr, s);
	io_hook_take(avr, spdr, spi_read_spdr, spi_write_spdr, s);
	io_hook_register_last(avr, &s->io);
	spi_reset(&s->io);
}
