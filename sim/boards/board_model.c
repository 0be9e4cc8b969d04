/*
 * board_model.c: pins, compare outputs, external drive, analog inputs and
 * the SPI pins of a board (board_model.h).
 */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "sim_regbit.h"
#include "avr_adc.h"

#include "boards/board_model.h"
#include "boards/sram.h"
#include "periph/io_hook.h"
#include "simavr16/timers.h"

/* --- pins ---------------------------------------------------------------- */

static int bm_oc_on(const bm_oc_t *oc)
{
	return avr_regbit_get(oc->bm->avr, oc->timer->comp[oc->comp].com) != 0;
}

/* The compare unit driving pin BIT, or NULL. */
static const bm_oc_t *bm_pin_oc(const bm_port_t *p, int bit)
{
	const bm_oc_t *best = NULL;

	for (int i = 0; i < p->noc[bit]; i++) {
		const bm_oc_t *oc = p->oc[bit][i];

		if (bm_oc_on(oc) && (!best || oc->seq > best->seq)) {
			best = oc;
		}
	}
	return best;
}

static int bm_pin_level(const bm_port_t *p, int bit)
{
	uint8_t m = (uint8_t)(1u << bit);

	if (p->wired & m) {
		const board_model_t *bm = p->bm;

		return bit == bm->twi_scl ? bm->twi_bus->scl : bm->twi_bus->sda;
	}
	if (p->uart_mask & m) {
		return !!(p->uart_level & m);
	}
	if (p->spi_mask & p->spi_input & m) {
		return !!(p->spi_level & m);
	}
	if (p->ddr & m) {
		if (p->spi_mask & m) {
			return !!(p->spi_level & m);
		}
		const bm_oc_t *oc = bm_pin_oc(p, bit);

		return oc ? oc->latch : !!(p->port & m);
	}
	if (p->ext_mask & m) {
		return !!(p->ext_value & m);
	}
	return !!(p->port & m);
}

/* The pins of MASK. */
static void bm_port_update_pins(bm_port_t *p, uint8_t mask, uint64_t cycle)
{
	avr_t *avr = p->bm->avr;

	for (int b = 0; b < 8; b++) {
		int level;
		uint8_t m = (uint8_t)(1u << b);

		if (!(mask & m)) {
			continue;
		}
		level = bm_pin_level(p, b);

		if (!(p->ddr & m) && !(p->ext_mask & m) &&
		    !!(avr->data[p->io->r_pin] & m) != level) {
			avr_raise_irq(p->irq + b, (uint32_t)level);
		}
		signal_set(&p->pin[b], cycle, level);
	}
}

void board_model_port_update(bm_port_t *p, uint64_t cycle)
{
	bm_port_update_pins(p, 0xff, cycle);
}

/* PINx of an output reads the pin's real level: simavr returns PORTx,
 * stale while a compare unit or the SPI drives the pin. */
static uint8_t bm_read_pin(avr_t *avr, avr_io_addr_t addr, void *param)
{
	bm_port_t *p = param;
	uint8_t v = io_hook_pass_read(avr, &p->pin_read, addr);
	uint8_t levels = 0;

	for (int b = 0; b < 8; b++) {
		levels |= (uint8_t)(p->pin[b].level << b);
	}
	uint8_t own = (uint8_t)(p->ddr | p->wired | p->uart_mask | (p->spi_mask & p->spi_input));

	v = (uint8_t)((v & ~own) | (levels & own));
	avr->data[addr] = v;
	return v;
}

static void bm_on_port(struct avr_irq_t *irq, uint32_t value, void *param)
{
	bm_port_t *p = param;

	(void)irq;
	p->port = (uint8_t)value;
	board_model_port_update(p, p->bm->avr->cycle);
}

static void bm_on_ddr(struct avr_irq_t *irq, uint32_t value, void *param)
{
	bm_port_t *p = param;

	(void)irq;
	p->ddr = (uint8_t)value;
	board_model_port_update(p, p->bm->avr->cycle);
}

static void bm_on_oc(struct avr_irq_t *irq, uint32_t value, void *param)
{
	bm_oc_t *oc = param;

	(void)irq;
	if (!simavr16_oc_event_real(oc->bm->avr, oc->timer, oc->comp)) {
		return;
	}
	oc->latch = value & 1;
	oc->seq = ++oc->bm->oc_seq;
	board_model_port_update(oc->port, simavr16_event_cycle(oc->bm->avr, oc->timer));
}

static void bm_update_oc_ports(board_model_t *bm)
{
	for (int i = 0; i < bm->noc; i++) {
		board_model_port_update(bm->oc[i].port, bm->avr->cycle);
	}
}

/* A register holding COM bits was written: the pin may change owner. */
static void bm_on_com_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	bm_com_hook_t *h = param;

	io_hook_pass_write(avr, &h->prev, addr, v);
	bm_update_oc_ports(h->bm);
}

static void bm_hook_com(board_model_t *bm, uint16_t addr)
{
	for (int i = 0; i < bm->ncom; i++) {
		if (bm->com[i].addr == addr) {
			return;
		}
	}
	if (bm->ncom == (int)(sizeof(bm->com) / sizeof(bm->com[0]))) {
		return;
	}
	bm_com_hook_t *h = &bm->com[bm->ncom++];

	h->bm = bm;
	h->addr = addr;
	io_hook_chain(bm->avr, addr, NULL, bm_on_com_write, h, &h->prev);
}

bm_port_t *board_model_port(board_model_t *bm, char letter)
{
	letter = (char)toupper((unsigned char)letter);
	for (int i = 0; i < bm->nports; i++) {
		if (bm->ports[i].name == letter) {
			return &bm->ports[i];
		}
	}
	return NULL;
}

int board_model_parse_pin(board_model_t *bm, const char *s, bm_port_t **port, int *bit)
{
	if (!s || strlen(s) != 2 || s[1] < '0' || s[1] > '7') {
		return -1;
	}
	*port = board_model_port(bm, s[0]);
	*bit = s[1] - '0';
	return *port ? 0 : -1;
}

void board_model_drive(board_model_t *bm, bm_port_t *p, int bit, int level)
{
	uint8_t m = (uint8_t)(1u << bit);
	avr_ioport_external_t ext = { .name = (unsigned)p->name };

	if (level < 0) {
		p->ext_mask &= (uint8_t)~m;
		p->ext_value &= (uint8_t)~m;
	} else {
		p->ext_mask |= m;
		p->ext_value = (uint8_t)(level ? (p->ext_value | m) : (p->ext_value & ~m));
	}
	ext.mask = p->ext_mask;
	ext.value = p->ext_value;
	avr_ioctl(bm->avr, AVR_IOCTL_IOPORT_SET_EXTERNAL(p->name), &ext);
	if (level >= 0) {
		avr_raise_irq(p->irq + bit, (uint32_t)level);
	}
	board_model_port_update(p, bm->avr->cycle);
	bm->activity++;
}

void board_model_uart_drive(board_model_t *bm, bm_port_t *p, int bit, int level,
			    uint64_t cycle)
{
	uint8_t m = (uint8_t)(1u << bit);

	p->uart_mask = (uint8_t)(level >= 0 ? (p->uart_mask | m) : (p->uart_mask & ~m));
	p->uart_level = (uint8_t)(level > 0 ? (p->uart_level | m) : (p->uart_level & ~m));
	board_model_port_update(p, cycle);
	bm->activity++;
}

void board_model_pin_text(board_model_t *bm, bm_port_t *p, int bit, char *buf, int size)
{
	uint8_t m = (uint8_t)(1u << bit);
	const char *how;

	(void)bm;
	if (p->uart_mask & m) {
		how = "out uart";
	} else if (p->spi_mask & p->spi_input & m) {
		how = "in spi";
	} else if (p->ddr & m) {
		how = (p->spi_mask & m) ? "out spi" : bm_pin_oc(p, bit) ? "out oc" : "out";
	} else if (p->ext_mask & m) {
		how = "in ext";
	} else if (p->port & m) {
		how = "in pullup";
	} else {
		how = "in";
	}
	snprintf(buf, (size_t)size, "%d %s", p->pin[bit].level, how);
}

/* --- SPI pins -------------------------------------------------------------- */

static void bm_spi_drive(void *param, int pin, int active, int level, uint64_t cycle)
{
	board_model_t *bm = param;
	bm_port_t *p = bm->spi_port[pin];

	if (!p) {
		return;
	}
	uint8_t m = (uint8_t)(1u << bm->spi_bit[pin]);

	p->spi_mask = (uint8_t)(active ? (p->spi_mask | m) : (p->spi_mask & ~m));
	p->spi_level = (uint8_t)(level ? (p->spi_level | m) : (p->spi_level & ~m));
	board_model_port_update(p, cycle);
}

spi_dev_t *board_model_spi_dev(board_model_t *bm, const char *pin)
{
	for (int i = 0; i < bm->spi.ndev; i++) {
		if (strcasecmp(bm->spi.dev[i]->cs->name, pin) == 0) {
			return bm->spi.dev[i];
		}
	}
	return NULL;
}

const char *board_model_add_spi(board_model_t *bm, const char *spec)
{
	char buf[64], *at, *opt, *save = NULL;
	int mode = 0, lsb = 0;
	bm_port_t *p;
	int bit;
	spi_dev_t *d;
	const part_kind_t *kind;

	if (strlen(spec) >= sizeof(buf)) {
		return "too long";
	}
	strcpy(buf, spec);
	at = strchr(buf, '@');
	if (!at) {
		return "expected KIND@PIN";
	}
	*at++ = 0;
	char *pin = strtok_r(at, ":", &save);

	if (!pin || board_model_parse_pin(bm, pin, &p, &bit) < 0) {
		return "bad chip-select pin";
	}
	if (board_model_spi_dev(bm, p->pin[bit].name)) {
		return "two devices on one chip-select pin";
	}
	while ((opt = strtok_r(NULL, ":", &save))) {
		if (strncmp(opt, "mode=", 5) == 0 && opt[5] >= '0' && opt[5] <= '3' && !opt[6]) {
			mode = opt[5] - '0';
		} else if (strcmp(opt, "lsb") == 0) {
			lsb = 1;
		} else if (strcmp(opt, "msb") == 0) {
			lsb = 0;
		} else {
			return "bad option (mode=0..3, lsb, msb)";
		}
	}
	kind = part_kind_find(buf, PART_SPI);
	if (!kind) {
		static char unknown[96];
		char names[64];

		snprintf(unknown, sizeof(unknown), "unknown kind (%s) or too many",
			 part_kind_names(PART_SPI, ", ", names, sizeof(names)));
		return unknown;
	}
	part_env_t env = { .adc_mv = bm->adc_mv, .avcc = &bm->avcc, .opts = "" };
	const char *err = NULL;

	if (bm->spi.ndev == SPI_MAX_DEVICES) {
		return "too many SPI devices";
	}
	d = part_make(kind, &env, &err);
	if (!d) {
		return err;
	}
	d->kind = kind->name;
	d->mode = mode;
	d->lsb_first = lsb;
	if (spi_attach(&bm->spi, d, &p->pin[bit]) < 0) {
		return "too many SPI devices";
	}
	part_list_add(&bm->spi_parts, kind, d, 0);
	return NULL;
}

/* --- analog ---------------------------------------------------------------- */

void board_model_set_adc(board_model_t *bm, int ch, uint32_t mv)
{
	bm->adc_mv[ch] = mv;
	if (bm->adc_irq) {
		avr_raise_irq(bm->adc_irq + ADC_IRQ_ADC0 + ch, mv);
	}
	bm->activity++;
}

void board_model_set_avcc(board_model_t *bm, uint32_t mv)
{
	bm->avcc = mv;
	bm->avr->avcc = mv;
	bm->avr->vcc = mv;
	bm->activity++;
}

void board_model_set_aref(board_model_t *bm, uint32_t mv)
{
	bm->aref = mv;
	bm->avr->aref = mv;
	bm->activity++;
}

/* --- setup ----------------------------------------------------------------- */

static void bm_reset(avr_io_t *io)
{
	board_model_t *bm = (board_model_t *)io;
	avr_t *avr = bm->avr;

	/* avr_reset cleared the port registers without telling the IRQs: their
	 * values are the old registers', and simavr raises a filtered IRQ only
	 * when the value changes, so a firmware writing after a watchdog reset
	 * what it wrote before went unseen. The IRQs learn the reset values. */
	for (int i = 0; i < bm->nports; i++) {
		bm_port_t *p = &bm->ports[i];

		p->ddr = avr->data[p->io->r_ddr];
		p->port = avr->data[p->io->r_port];
		p->irq[IOPORT_IRQ_REG_PORT].value = p->port;
		p->irq[IOPORT_IRQ_DIRECTION_ALL].value = p->ddr;
		board_model_port_update(p, avr->cycle);
	}
	avr->avcc = bm->avcc;
	avr->vcc = bm->avcc;
	avr->aref = bm->aref;
	simavr16_no_strict_level(avr);
	if (bm->reset_cause && !strcmp(bm->reset_cause, "power")) {
		sram_paint(avr);
	}
}

static int bm_find_ports(board_model_t *bm)
{
	char name[4];

	for (avr_io_t *io = bm->avr->io_port; io; io = io->next) {
		if (!io->kind || strcmp(io->kind, "port") != 0 || bm->nports == BM_MAX_PORTS) {
			continue;
		}
		avr_ioport_t *ap = (avr_ioport_t *)io;
		bm_port_t *p = &bm->ports[bm->nports++];

		p->bm = bm;
		p->name = ap->name;
		p->io = ap;
		p->irq = avr_io_getirq(bm->avr, AVR_IOCTL_IOPORT_GETIRQ(ap->name), 0);
		if (!p->irq) {
			return -1;
		}
	}
	/* signals in port order, A0..G7 */
	for (char c = 'A'; c <= 'Z'; c++) {
		bm_port_t *p = board_model_port(bm, c);

		for (int b = 0; p && b < 8; b++) {
			snprintf(name, sizeof(name), "%c%d", c, b);
			if (signal_add(&bm->signals, &p->pin[b], name, 0) < 0) {
				return -1;
			}
		}
		if (p) {
			io_hook_chain(bm->avr, p->io->r_pin, bm_read_pin, NULL, p, &p->pin_read);
			avr_irq_register_notify(p->irq + IOPORT_IRQ_REG_PORT, bm_on_port, p);
			avr_irq_register_notify(p->irq + IOPORT_IRQ_DIRECTION_ALL, bm_on_ddr, p);
		}
	}
	return 0;
}

static void bm_find_ocs(board_model_t *bm)
{
	for (avr_io_t *io = bm->avr->io_port; io; io = io->next) {
		if (!io->kind || strcmp(io->kind, "timer") != 0) {
			continue;
		}
		avr_timer_t *t = (avr_timer_t *)io;

		for (int c = 0; c < AVR_TIMER_COMP_COUNT; c++) {
			avr_regbit_t pin = t->comp[c].com_pin;

			if (!pin.reg || !t->comp[c].com.reg || bm->noc == BM_MAX_OC) {
				continue;
			}
			for (int i = 0; i < bm->nports; i++) {
				bm_port_t *p = &bm->ports[i];

				if (p->io->r_port != pin.reg || p->noc[pin.bit] == 2) {
					continue;
				}
				bm_oc_t *oc = &bm->oc[bm->noc++];

				oc->bm = bm;
				oc->timer = t;
				oc->comp = c;
				oc->port = p;
				oc->bit = pin.bit;
				p->oc[pin.bit][p->noc[pin.bit]++] = oc;
				avr_irq_register_notify(t->io.irq + TIMER_IRQ_OUT_COMP + c,
							bm_on_oc, oc);
				bm_hook_com(bm, t->comp[c].com.reg);
			}
		}
	}
}

int board_model_init(board_model_t *bm, avr_t *avr, const sim_board_desc_t *board,
		     const sim_mcu_t *mcu, trace_t *trace)
{
	const sim_wiring_t *w = &board->wiring;

	memset(bm, 0, sizeof(*bm));
	bm->avr = avr;
	bm->board = board;
	bm->wiring = w;
	bm->trace = trace;
	if (bm_find_ports(bm) < 0) {
		return -1;
	}
	bm_find_ocs(bm);
	simavr16_timers_init(bm, mcu);
	if (board_model_wire_servos(bm) < 0) {
		return -1;
	}
	bm->adc_irq = avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0);
	board_model_set_avcc(bm, 5000);
	board_model_set_aref(bm, 5000);

	static const int spi_fn[SPI_PINS] = {
		[SPI_PIN_SCK] = BF_SPI_SCK, [SPI_PIN_MOSI] = BF_SPI_MOSI, [SPI_PIN_MISO] = BF_SPI_MISO,
	};
	for (int k = 0; k < SPI_PINS; k++) {
		const sim_pin_t *bp = sim_wiring_pin(w, spi_fn[k], 0);

		bm->spi_port[k] = bp ? board_model_port(bm, bp->port) : NULL;
		bm->spi_bit[k] = bp ? bp->bit : 0;
	}
	if (bm->spi_port[SPI_PIN_MISO]) {
		bm->spi_port[SPI_PIN_MISO]->spi_input = (uint8_t)(1u << bm->spi_bit[SPI_PIN_MISO]);
	}
	spi_init(&bm->spi, avr, mcu->spi.spcr, mcu->spi.spsr, mcu->spi.spdr,
		 mcu->spi.vect_spi, trace, bm_spi_drive, bm);

	bm->io.kind = "orfa-board";
	bm->io.reset = bm_reset;
	io_hook_register_last(avr, &bm->io);
	sram_paint(avr);
	bm->activity = 0;
	return 0;
}

static void bm_twi_lines(void *param, int scl_line, uint64_t cycle)
{
	board_model_t *bm = param;

	/* only the pin of the line that moved: this runs on every edge of the bus */
	bm_port_update_pins(bm->twi_port, (uint8_t)(1u << (scl_line ? bm->twi_scl : bm->twi_sda)),
			    cycle);
}

int board_model_wire_twi(board_model_t *bm, twi_bus_t *bus)
{
	const sim_pin_t *scl = sim_wiring_pin(bm->wiring, BF_TWI_SCL, 0);
	const sim_pin_t *sda = sim_wiring_pin(bm->wiring, BF_TWI_SDA, 0);
	bm_port_t *p = scl && sda ? board_model_port(bm, scl->port) : NULL;

	if (!p || sda->port != scl->port || twi_bus_listen(bus, bm_twi_lines, bm) < 0) {
		return -1;
	}
	bm->twi_bus = bus;
	bm->twi_port = p;
	bm->twi_scl = scl->bit;
	bm->twi_sda = sda->bit;
	p->wired = (uint8_t)((1u << scl->bit) | (1u << sda->bit));
	board_model_port_update(p, bm->avr->cycle);
	return 0;
}
