/*
 * board_model.c: pins, compare outputs, external drive, analog inputs,
 * servo counters and SPI devices of a board.
 */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "sim_regbit.h"
#include "avr_adc.h"

#include "avr_extint.h"
#include "board_model.h"

_Static_assert(MAX_CYCLE_TIMERS <= 64, "the slot mask is 64 bits");

/*
 * The cycle an event really happened at. simavr runs cycle timers after
 * the instruction that crossed their time, so avr->cycle may be a few
 * cycles late; a compare match's pin change belongs to the timer's own
 * cycle. While a cycle timer runs, its slot is in neither of the pool's
 * lists and still holds that cycle: find it by the timer's param.
 */
static avr_cycle_timer_slot_p bm_event_slot(avr_t *avr, void *param)
{
	avr_cycle_timer_pool_t *pool = &avr->cycle_timers;
	uint64_t listed = 0;

	for (avr_cycle_timer_slot_p t = pool->timer; t; t = t->next) {
		listed |= 1ull << (t - pool->timer_slots);
	}
	for (avr_cycle_timer_slot_p t = pool->timer_free; t; t = t->next) {
		listed |= 1ull << (t - pool->timer_slots);
	}
	for (int i = 0; i < MAX_CYCLE_TIMERS; i++) {
		avr_cycle_timer_slot_p t = &pool->timer_slots[i];

		if (!(listed & (1ull << i)) && t->param == param && t->when <= avr->cycle) {
			return t;
		}
	}
	return NULL;
}

static uint64_t bm_event_cycle(avr_t *avr, void *param)
{
	avr_cycle_timer_slot_p t = bm_event_slot(avr, param);

	return t ? t->when : avr->cycle;
}

/*
 * Whether a compare output change simavr reports is one a real AVR makes.
 * simavr 1.6 gives every mode fast-PWM rules: at each overflow, and each
 * time an OCR, TCNT or mode write re-plans the timer, it drives every
 * compare output whose match is still ahead to its "before the match"
 * level (set-on-match to 0, clear-on-match to 1). In normal and CTC modes
 * an AVR's OCnx changes on a compare match only, so those are dropped:
 * a servo counter's clock line would otherwise get an edge of its own at
 * every Timer3 overflow (an extra CD4017 step, a slot skipped).
 * Real matches come from the comparator's own cycle timer (its time is
 * the overflow's plus the compare's, never the overflow's own), or, for
 * a compare at TOP, straight from the overflow timer.
 */
static int bm_oc_event_real(avr_t *avr, const avr_timer_t *t, int comp)
{
	if (t->wgm_op_mode_kind != avr_timer_wgm_normal && t->wgm_op_mode_kind != avr_timer_wgm_ctc) {
		return 1;
	}
	if (t->ext_clock_flags & (AVR_TIMER_EXTCLK_FLAG_TN | AVR_TIMER_EXTCLK_FLAG_AS2)) {
		return 1;	/* clocked from a pin: simavr's other path */
	}
	avr_cycle_timer_slot_p slot = bm_event_slot(avr, (void *)t);

	if (!slot) {
		return 0;	/* a register write re-planning the timer */
	}
	if (slot->when != t->tov_base) {
		return 1;	/* the comparator's own timer */
	}
	return t->comp[comp].comp_cycles == t->tov_cycles;
}

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

/* Recompute every pin of P at CYCLE; an input's PINx bit follows. */
static void bm_port_update(bm_port_t *p, uint64_t cycle)
{
	avr_t *avr = p->bm->avr;

	for (int b = 0; b < 8; b++) {
		int level = bm_pin_level(p, b);
		uint8_t m = (uint8_t)(1u << b);

		if (!(p->ddr & m) && !(p->ext_mask & m) &&
		    !!(avr->data[p->io->r_pin] & m) != level) {
			avr_raise_irq(p->irq + b, (uint32_t)level);
		}
		signal_set(&p->pin[b], cycle, level);
	}
}

/* PINx of an output reads the pin's real level: simavr returns PORTx,
 * stale while a compare unit or the SPI drives the pin. */
static uint8_t bm_read_pin(avr_t *avr, avr_io_addr_t addr, void *param)
{
	bm_port_t *p = param;
	uint8_t v = p->pin_read ? p->pin_read(avr, addr, p->pin_read_param) : avr->data[addr];
	uint8_t levels = 0;

	for (int b = 0; b < 8; b++) {
		levels |= (uint8_t)(p->pin[b].level << b);
	}
	uint8_t own = (uint8_t)(p->ddr | p->wired);

	v = (uint8_t)((v & ~own) | (levels & own));
	avr->data[addr] = v;
	return v;
}

static void bm_on_port(struct avr_irq_t *irq, uint32_t value, void *param)
{
	bm_port_t *p = param;

	(void)irq;
	p->port = (uint8_t)value;
	bm_port_update(p, p->bm->avr->cycle);
}

static void bm_on_ddr(struct avr_irq_t *irq, uint32_t value, void *param)
{
	bm_port_t *p = param;

	(void)irq;
	p->ddr = (uint8_t)value;
	bm_port_update(p, p->bm->avr->cycle);
}

static void bm_on_oc(struct avr_irq_t *irq, uint32_t value, void *param)
{
	bm_oc_t *oc = param;

	(void)irq;
	if (!bm_oc_event_real(oc->bm->avr, oc->timer, oc->comp)) {
		return;
	}
	oc->latch = value & 1;
	oc->seq = ++oc->bm->oc_seq;
	bm_port_update(oc->port, bm_event_cycle(oc->bm->avr, oc->timer));
}

static void bm_update_oc_ports(board_model_t *bm)
{
	for (int i = 0; i < bm->noc; i++) {
		bm_port_update(bm->oc[i].port, bm->avr->cycle);
	}
}

/* Takes over the write handler of the register at ADDR, keeping the one it
 * had (simavr's) in PREV for bm_pass_write. */
static void bm_take_write(avr_t *avr, uint16_t addr, avr_io_write_t fn, void *param,
			  bm_chain_t *prev)
{
	avr_io_addr_t io = AVR_DATA_TO_IO(addr);

	prev->w = avr->io[io].w.c;
	prev->param = avr->io[io].w.param;
	avr->io[io].w.c = fn;
	avr->io[io].w.param = param;
}

/* The write as the register's own handler (or a plain store) does it. */
static void bm_pass_write(avr_t *avr, const bm_chain_t *prev, uint16_t addr, uint8_t v)
{
	if (prev->w) {
		prev->w(avr, addr, v, prev->param);
	} else {
		avr->data[addr] = v;
	}
}

/* A register holding COM bits was written: the pin may change owner. */
static void bm_on_com_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	bm_com_hook_t *h = param;

	bm_pass_write(avr, &h->prev, addr, v);
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
	bm_take_write(bm->avr, addr, bm_on_com_write, h, &h->prev);
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
	bm_port_update(p, bm->avr->cycle);
	bm->activity++;
}

void board_model_pin_text(board_model_t *bm, bm_port_t *p, int bit, char *buf, int size)
{
	uint8_t m = (uint8_t)(1u << bit);
	const char *how;

	(void)bm;
	if (p->ddr & m) {
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
	bm_port_update(p, cycle);
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
	if (strcmp(buf, "eeprom25") == 0 && bm->nee < BM_MAX_SPI_DEV) {
		eeprom25_init(&bm->ee[bm->nee], mode, lsb);
		d = &bm->ee[bm->nee++].dev;
	} else if (strcmp(buf, "mcp3008") == 0 && bm->nmcp < BM_MAX_SPI_DEV) {
		mcp3008_init(&bm->mcp[bm->nmcp], mode, lsb, bm->adc_mv, &bm->avcc);
		d = &bm->mcp[bm->nmcp++].dev;
	} else {
		return "unknown kind (eeprom25, mcp3008) or too many";
	}
	if (spi_attach(&bm->spi, d, &p->pin[bit]) < 0) {
		return "too many SPI devices";
	}
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

/* --- servo counters -------------------------------------------------------- */

static void bm_servo_mirror(void *param, signal_t *s, uint64_t cycle, int level)
{
	(void)s;
	signal_set(param, cycle, level);
}

static int bm_counters(board_model_t *bm)
{
	const board_wiring_t *w = bm->wiring;
	const board_pin_t *rst = board_wiring_pin(w, BW_SERVO_RST, 0);
	char name[16];

	for (int c = 0; c < w->servo_counters && c < 4; c++) {
		const board_pin_t *clk = board_wiring_pin(w, BW_SERVO_CLK, c);
		bm_port_t *cp = clk ? board_model_port(bm, clk->port) : NULL;

		snprintf(name, sizeof(name), "cnt%d", c);
		if (!cp || cd4017_init(&bm->cnt[c], &bm->signals, name) < 0) {
			return -1;
		}
		signal_listen(&cp->pin[clk->bit], cd4017_on_clock, &bm->cnt[c]);
		if (rst) {
			bm_port_t *rp = board_model_port(bm, rst->port);

			if (rp) {
				signal_listen(&rp->pin[rst->bit], cd4017_on_reset, &bm->cnt[c]);
			}
		}
		bm->ncnt++;
	}
	for (int n = 0; n < bm->ncnt * w->servo_per_counter && n < 32; n++) {
		int c = n / w->servo_per_counter, k = 1 + n % w->servo_per_counter;

		snprintf(name, sizeof(name), "servo%d", n);
		if (signal_add(&bm->signals, &bm->servo[n], name, 0) < 0) {
			return -1;
		}
		signal_listen(&bm->cnt[c].q[k], bm_servo_mirror, &bm->servo[n]);
		bm->nservo++;
	}
	return 0;
}

/* Servo channels on plain pins (the M32-D): "servo<n>" follows channel n's
 * pin, so servos are named alike on every board (`12/servo2`). */
static int bm_servo_pins(board_model_t *bm)
{
	const board_wiring_t *w = bm->wiring;
	char name[16];

	for (int n = 0; n < 32; n++) {
		const board_pin_t *p = board_wiring_pin(w, BW_SERVO, n);
		bm_port_t *port = p ? board_model_port(bm, p->port) : NULL;

		if (!port) {
			break;
		}
		snprintf(name, sizeof(name), "servo%d", n);
		if (signal_add(&bm->signals, &bm->servo[n], name, port->pin[p->bit].level) < 0) {
			return -1;
		}
		signal_listen(&port->pin[p->bit], bm_servo_mirror, &bm->servo[n]);
		bm->nservo++;
	}
	return 0;
}

/* --- setup ----------------------------------------------------------------- */

/* simavr polls a low INTn pin on every cycle ("strict" level triggering,
 * switched on again at each reset) even with the interrupt off: the M128-S
 * counter clocks sit low on INT4/INT5 and made the simulation ten times
 * slower. Level interrupts still fire, once per level change. */
static void bm_no_strict_level(avr_t *avr)
{
	for (uint8_t i = 0; i < 8; i++) {
		avr_extint_set_strict_lvl_trig(avr, i, 0);
	}
}

/* Stack painting: SRAM keeps its contents over a reset, as on silicon, so
 * the simulator fills it with BM_PAINT at power-on (start-up and `reset
 * power`), before the firmware starts; the startup code then initialises
 * .data and .bss, and the stack overwrites the paint as deep as it ever
 * goes. Other resets (watchdog, external, brown-out) keep SRAM: .noinit
 * data survive them, and the stack peak counts from power-on. */
static void bm_paint_sram(avr_t *avr)
{
	for (uint32_t a = avr->ioend + 1u; a <= avr->ramend; a++) {
		avr->data[a] = BM_PAINT;
	}
}

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
		bm_port_update(p, avr->cycle);
	}
	avr->avcc = bm->avcc;
	avr->vcc = bm->avcc;
	avr->aref = bm->aref;
	bm_no_strict_level(avr);
	if (bm->reset_cause && !strcmp(bm->reset_cause, "power")) {
		bm_paint_sram(avr);
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
			avr_io_addr_t io = AVR_DATA_TO_IO(p->io->r_pin);

			p->pin_read = bm->avr->io[io].r.c;
			p->pin_read_param = bm->avr->io[io].r.param;
			bm->avr->io[io].r.c = bm_read_pin;
			bm->avr->io[io].r.param = p;
			avr_irq_register_notify(p->irq + IOPORT_IRQ_REG_PORT, bm_on_port, p);
			avr_irq_register_notify(p->irq + IOPORT_IRQ_DIRECTION_ALL, bm_on_ddr, p);
		}
	}
	return 0;
}

/* simavr 1.6 does not apply an OCRnx written while the timer runs in a PWM
 * mode with TOP = ICRn: the compare keeps the value it had when the timer
 * started (a compare interrupt reading TCNT shows it). After such a write the
 * board model waits for the end of the PWM period, as silicon's double
 * buffer does, and there stops and restarts the timer's clock through
 * simavr's own TCCRnB handler, which re-plans the compares from the
 * registers; the new period starts from 0 as it would anyway. */
static void bm_io_write(avr_t *avr, uint16_t addr, uint8_t v)
{
	avr_io_addr_t io = AVR_DATA_TO_IO(addr);

	if (avr->io[io].w.c) {
		avr->io[io].w.c(avr, addr, v, avr->io[io].w.param);
	} else {
		avr->data[addr] = v;
	}
}

static uint8_t bm_cs_mask(const avr_timer_t *t)
{
	uint8_t mask = 0;

	for (int i = 0; i < (int)(sizeof(t->cs) / sizeof(t->cs[0])); i++) {
		if (t->cs[i].reg == t->cs[0].reg) {
			mask |= (uint8_t)(t->cs[i].mask << t->cs[i].bit);
		}
	}
	return mask;
}

static avr_cycle_count_t bm_ocr_latch(avr_t *avr, avr_cycle_count_t when, void *param)
{
	avr_timer_t *t = param;
	uint16_t cs_reg = t->cs[0].reg;
	uint8_t cs_val = avr->data[cs_reg];

	(void)when;
	if (cs_val & bm_cs_mask(t)) {
		bm_io_write(avr, cs_reg, (uint8_t)(cs_val & ~bm_cs_mask(t)));
		bm_io_write(avr, cs_reg, cs_val);
	}
	return 0;
}

static void bm_on_ocr_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	bm_ocr_hook_t *h = param;
	avr_timer_t *t = h->timer;

	bm_pass_write(avr, &h->prev, addr, v);
	/* (avr_timer_wgm_pwm, simavr's filing of the ATmega32's mode 14, is
	 * latched at each overflow by bm_on_pwm_overflow instead.) */
	if (t->wgm_op_mode_kind != avr_timer_wgm_fast_pwm
	    || !(avr->data[t->cs[0].reg] & bm_cs_mask(t)) || !t->tov_cycles
	    || avr_cycle_timer_status(avr, bm_ocr_latch, t)) {
		return;
	}
	/* One cycle before the overflow: the restart then takes the overflow's
	 * place (at the overflow itself simavr's own overflow timer and this
	 * one race, and a period may lose its compare). */
	avr_cycle_count_t end = t->tov_base + t->tov_cycles - 1;
	avr_cycle_timer_register(avr, end > avr->cycle ? end - avr->cycle : 1, bm_ocr_latch, t);
}

/*
 * A PWM timer's overflow (BOTTOM), from inside simavr's overflow timer,
 * before it plans the period's compares. simavr 1.6 files the ATmega32's
 * mode 14 (fast PWM, TOP = ICR1) as avr_timer_wgm_pwm and then ignores OCR
 * writes while the timer runs; silicon takes a new OCR1x at BOTTOM (double
 * buffer). So each compare's time is set here from the OCR registers, as
 * simavr's own configure would. And when simavr runs the overflow timer
 * late (after a multi-cycle instruction) it skips every compare whose time
 * has already passed in the new period: an OCR of 0 or 1 (a 1- or 2-cycle
 * pulse) then loses its pulse. The model makes that pulse itself.
 */
static void bm_on_pwm_overflow(struct avr_irq_t *irq, uint32_t value, void *param)
{
	bm_pwm_timer_t *pw = param;
	board_model_t *bm = pw->bm;
	avr_t *avr = bm->avr;
	avr_timer_t *t = pw->timer;

	(void)irq;
	if (!value || t->wgm_op_mode_kind != avr_timer_wgm_pwm || !t->tov_cycles) {
		return;
	}
	avr_cycle_timer_slot_p slot = bm_event_slot(avr, t);

	if (!slot) {
		return;
	}
	uint64_t when = slot->when;

	for (int c = 0; c < AVR_TIMER_COMP_COUNT; c++) {
		if (!t->comp[c].r_ocr) {
			continue;
		}
		uint32_t ocr = avr->data[t->comp[c].r_ocr] |
			       (t->comp[c].r_ocrh ? (uint32_t)avr->data[t->comp[c].r_ocrh] << 8 : 0u);
		uint32_t cc = ocr <= t->tov_top ? t->cs_div_value * (ocr + 1u) : 0u;

		t->comp[c].comp_cycles = cc;
		if (!cc || cc >= t->tov_cycles || cc >= avr->cycle - when) {
			continue;	/* simavr plans this one itself */
		}
		int com = avr_regbit_get(avr, t->comp[c].com);

		if (com != 2 && com != 3) {
			continue;
		}
		for (int i = 0; i < bm->noc; i++) {
			bm_oc_t *oc = &bm->oc[i];

			if (oc->timer != t || oc->comp != c) {
				continue;
			}
			oc->latch = com == 2;	/* BOTTOM: set (clear-on-match mode) */
			oc->seq = ++bm->oc_seq;
			bm_port_update(oc->port, when);
			oc->latch = com != 2;	/* the match */
			bm_port_update(oc->port, when + cc);
		}
	}
}

static void bm_watch_pwm(board_model_t *bm, avr_timer_t *t)
{
	for (int i = 0; i < bm->npwm; i++) {
		if (bm->pwm[i].timer == t) {
			return;
		}
	}
	if (bm->npwm == (int)(sizeof(bm->pwm) / sizeof(bm->pwm[0])) || !t->overflow.vector) {
		return;
	}
	bm_pwm_timer_t *pw = &bm->pwm[bm->npwm++];

	pw->bm = bm;
	pw->timer = t;
	avr_irq_register_notify(t->overflow.irq + AVR_INT_IRQ_PENDING, bm_on_pwm_overflow, pw);
}

static void bm_hook_ocr(board_model_t *bm, avr_timer_t *t, uint16_t addr)
{
	if (!addr || !t->r_tcnth) {
		return;	/* 16-bit timers only (the motor PWM) */
	}
	for (int i = 0; i < bm->nocr; i++) {
		if (bm->ocr[i].addr == addr) {
			return;
		}
	}
	if (bm->nocr == BM_MAX_OC) {
		return;
	}
	bm_ocr_hook_t *h = &bm->ocr[bm->nocr++];

	h->bm = bm;
	h->timer = t;
	h->addr = addr;
	bm_take_write(bm->avr, addr, bm_on_ocr_write, h, &h->prev);
}

/*
 * Writing TIFR / ETIFR: a 1 clears that flag, a 0 leaves it. simavr 1.6
 * clears every timer flag that is set whatever the value (docs/simulator.md),
 * so one flag cleared before enabling an interrupt would drop another
 * counter's pending compare. The board model owns these registers.
 */
static void bm_on_flag_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	bm_flag_reg_t *r = param;

	(void)addr;
	for (int i = 0; i < r->n; i++) {
		avr_int_vector_t *vec = r->vec[i];
		uint8_t m = (uint8_t)(vec->raised.mask << vec->raised.bit);

		if ((v & m) && avr_regbit_get(avr, vec->raised)) {
			avr_clear_interrupt(avr, vec);
		}
	}
}

static void bm_add_flag(board_model_t *bm, avr_int_vector_t *vec)
{
	bm_flag_reg_t *r = NULL;

	if (!vec->vector || !vec->raised.reg) {
		return;
	}
	for (int i = 0; i < bm->nflag_regs; i++) {
		if (bm->flag_regs[i].addr == vec->raised.reg) {
			r = &bm->flag_regs[i];
		}
	}
	if (!r) {
		if (bm->nflag_regs == (int)(sizeof(bm->flag_regs) / sizeof(bm->flag_regs[0]))) {
			return;
		}
		r = &bm->flag_regs[bm->nflag_regs++];
		r->addr = vec->raised.reg;
		/* replaced, not chained: simavr's own handler is the bug */
		bm_chain_t simavrs;
		bm_take_write(bm->avr, r->addr, bm_on_flag_write, r, &simavrs);
	}
	if (r->n < BM_MAX_FLAGS) {
		r->vec[r->n++] = vec;
	}
}

static void bm_own_timer_flags(board_model_t *bm)
{
	for (avr_io_t *io = bm->avr->io_port; io; io = io->next) {
		if (!io->kind || strcmp(io->kind, "timer") != 0) {
			continue;
		}
		avr_timer_t *t = (avr_timer_t *)io;

		bm_add_flag(bm, &t->overflow);
		bm_add_flag(bm, &t->icr);
		for (int c = 0; c < AVR_TIMER_COMP_COUNT; c++) {
			bm_add_flag(bm, &t->comp[c].interrupt);
		}
	}
}

/*
 * A forced compare (FOCnx written 1): in normal and CTC modes the unit acts
 * on its pin as on a match (toggle, clear, set by its COM bits), with no
 * interrupt flag; in PWM modes the strobe does nothing. The FOC bits read 0.
 */
static void bm_on_foc_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	bm_foc_hook_t *h = param;
	uint8_t strobes = 0;

	for (int i = 0; i < h->n; i++) {
		strobes |= (uint8_t)(1u << h->bit[i]);
	}
	bm_pass_write(avr, &h->prev, addr, (uint8_t)(v & ~strobes));
	for (int i = 0; i < h->n; i++) {
		bm_oc_t *oc = h->oc[i];
		const avr_timer_t *t = oc->timer;

		if (!(v & (1u << h->bit[i])) ||
		    (t->wgm_op_mode_kind != avr_timer_wgm_normal && t->wgm_op_mode_kind != avr_timer_wgm_ctc)) {
			continue;
		}
		switch (avr_regbit_get(avr, t->comp[oc->comp].com)) {
		case 1: oc->latch = !oc->latch; break;
		case 2: oc->latch = 0; break;
		case 3: oc->latch = 1; break;
		default: continue;
		}
		oc->seq = ++oc->bm->oc_seq;
		bm_port_update(oc->port, avr->cycle);
	}
}

static void bm_hook_foc(board_model_t *bm, const mcu_desc_t *mcu)
{
	for (int f = 0; f < mcu->foc_count; f++) {
		const mcu_foc_t *d = &mcu->foc[f];
		bm_oc_t *oc = NULL;
		bm_foc_hook_t *h = NULL;

		for (int i = 0; i < bm->noc; i++) {
			if (bm->oc[i].timer->name == d->timer && bm->oc[i].comp == d->comp) {
				oc = &bm->oc[i];
			}
		}
		if (!oc) {
			continue;	/* no pin on this board's MCU */
		}
		for (int i = 0; i < bm->nfoc; i++) {
			if (bm->foc[i].addr == d->reg) {
				h = &bm->foc[i];
			}
		}
		if (!h) {
			h = &bm->foc[bm->nfoc++];
			h->bm = bm;
			h->addr = d->reg;
			bm_take_write(bm->avr, d->reg, bm_on_foc_write, h, &h->prev);
		}
		if (h->n < 3) {
			h->oc[h->n] = oc;
			h->bit[h->n] = d->bit;
			h->n++;
		}
	}
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
				bm_hook_ocr(bm, t, t->comp[c].r_ocr);
				bm_watch_pwm(bm, t);
			}
		}
	}
}

int board_model_init(board_model_t *bm, avr_t *avr, const board_desc_t *board,
		     const mcu_desc_t *mcu, trace_t *trace)
{
	const board_wiring_t *w = board->wiring;

	memset(bm, 0, sizeof(*bm));
	bm->avr = avr;
	bm->board = board;
	bm->wiring = w;
	bm->trace = trace;
	if (bm_find_ports(bm) < 0) {
		return -1;
	}
	bm_find_ocs(bm);
	bm_own_timer_flags(bm);
	bm_hook_foc(bm, mcu);
	if (bm_counters(bm) < 0 || (!w->servo_counters && bm_servo_pins(bm) < 0)) {
		return -1;
	}
	bm->adc_irq = avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0);
	board_model_set_avcc(bm, 5000);
	board_model_set_aref(bm, 5000);

	for (int k = 0; k < 2; k++) {
		const board_pin_t *bp = board_wiring_pin(w, k ? BW_SPI_MOSI : BW_SPI_SCK, 0);

		bm->spi_port[k] = bp ? board_model_port(bm, bp->port) : NULL;
		bm->spi_bit[k] = bp ? bp->bit : 0;
	}
	spi_init(&bm->spi, avr, mcu->spi.spcr, mcu->spi.spsr, mcu->spi.spdr,
		 mcu->spi.vect_spi, trace, bm_spi_drive, bm);

	bm->io.kind = "orfa-board";
	bm->io.reset = bm_reset;
	mcu_register_io_last(avr, &bm->io);
	bm_no_strict_level(avr);
	bm_paint_sram(avr);
	bm->activity = 0;
	return 0;
}

static void bm_twi_lines(void *param, uint64_t cycle)
{
	board_model_t *bm = param;

	bm_port_update(bm->twi_port, cycle);
}

int board_model_wire_twi(board_model_t *bm, twi_bus_t *bus)
{
	const board_pin_t *scl = board_wiring_pin(bm->wiring, BW_TWI_SCL, 0);
	const board_pin_t *sda = board_wiring_pin(bm->wiring, BW_TWI_SDA, 0);
	bm_port_t *p = scl && sda ? board_model_port(bm, scl->port) : NULL;

	if (!p || sda->port != scl->port || twi_bus_listen(bus, bm_twi_lines, bm) < 0) {
		return -1;
	}
	bm->twi_bus = bus;
	bm->twi_port = p;
	bm->twi_scl = scl->bit;
	bm->twi_sda = sda->bit;
	p->wired = (uint8_t)((1u << scl->bit) | (1u << sda->bit));
	bm_port_update(p, bm->avr->cycle);
	return 0;
}

int board_model_stack_peak(board_model_t *bm, uint32_t from, uint32_t *deepest)
{
	avr_t *avr = bm->avr;
	uint32_t a;

	if (from == 0) {
		/* Not told where the static data end: the stack lies above the
		 * highest run of 16 untouched bytes. */
		uint32_t run = 0;
		for (a = avr->ramend; a > avr->ioend; a--) {
			run = (avr->data[a] == BM_PAINT) ? run + 1 : 0;
			if (run == 16) {
				break;
			}
		}
		from = a;
	}
	if (from <= avr->ioend || from > avr->ramend) {
		return -1;
	}
	for (a = from; a <= avr->ramend && avr->data[a] == BM_PAINT; a++) {
	}
	*deepest = a;
	return (int)(avr->ramend + 1u - a);
}
