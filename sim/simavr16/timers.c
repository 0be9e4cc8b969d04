/*
 * timers.c: repairs of simavr 1.6's timers, compare outputs and external
 * interrupts (timers.h). Delete with the upgrade to a simavr that has them
 * right; docs/simulator.md, "What simavr 1.6 gets wrong", lists each.
 */
#include <string.h>

#include "sim_regbit.h"
#include "avr_extint.h"

#include "boards/board_model.h"
#include "periph/io_hook.h"
#include "simavr16/timers.h"

_Static_assert(MAX_CYCLE_TIMERS <= 64, "the slot mask is 64 bits");

/*
 * The cycle an event really happened at. simavr runs cycle timers after
 * the instruction that crossed their time, so avr->cycle may be a few
 * cycles late; a compare match's pin change belongs to the timer's own
 * cycle. While a cycle timer runs, its slot is in neither of the pool's
 * lists and still holds that cycle: find it by the timer's param.
 */
static avr_cycle_timer_slot_p s16_event_slot(avr_t *avr, void *param)
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

uint64_t simavr16_event_cycle(avr_t *avr, void *param)
{
	avr_cycle_timer_slot_p t = s16_event_slot(avr, param);

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
int simavr16_oc_event_real(avr_t *avr, const avr_timer_t *t, int comp)
{
	if (t->wgm_op_mode_kind != avr_timer_wgm_normal && t->wgm_op_mode_kind != avr_timer_wgm_ctc) {
		return 1;
	}
	if (t->ext_clock_flags & (AVR_TIMER_EXTCLK_FLAG_TN | AVR_TIMER_EXTCLK_FLAG_AS2)) {
		return 1;	/* clocked from a pin: simavr's other path */
	}
	avr_cycle_timer_slot_p slot = s16_event_slot(avr, (void *)t);

	if (!slot) {
		return 0;	/* a register write re-planning the timer */
	}
	if (slot->when != t->tov_base) {
		return 1;	/* the comparator's own timer */
	}
	return t->comp[comp].comp_cycles == t->tov_cycles;
}

/* simavr polls a low INTn pin on every cycle ("strict" level triggering,
 * switched on again at each reset) even with the interrupt off: the M128-S
 * counter clocks sit low on INT4/INT5 and made the simulation ten times
 * slower. Level interrupts still fire, once per level change. */
void simavr16_no_strict_level(avr_t *avr)
{
	for (uint8_t i = 0; i < 8; i++) {
		avr_extint_set_strict_lvl_trig(avr, i, 0);
	}
}

static uint8_t s16_cs_mask(const avr_timer_t *t)
{
	uint8_t mask = 0;

	for (int i = 0; i < (int)(sizeof(t->cs) / sizeof(t->cs[0])); i++) {
		if (t->cs[i].reg == t->cs[0].reg) {
			mask |= (uint8_t)(t->cs[i].mask << t->cs[i].bit);
		}
	}
	return mask;
}

static avr_cycle_count_t s16_ocr_latch(avr_t *avr, avr_cycle_count_t when, void *param)
{
	avr_timer_t *t = param;
	uint16_t cs_reg = t->cs[0].reg;
	uint8_t cs_val = avr->data[cs_reg];

	(void)when;
	if (cs_val & s16_cs_mask(t)) {
		io_hook_write(avr, cs_reg, (uint8_t)(cs_val & ~s16_cs_mask(t)));
		io_hook_write(avr, cs_reg, cs_val);
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
static void s16_on_ocr_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	s16_ocr_hook_t *h = param;
	avr_timer_t *t = h->timer;

	io_hook_pass_write(avr, &h->prev, addr, v);
	/* (avr_timer_wgm_pwm, simavr's filing of the ATmega32's mode 14, is
	 * latched at each overflow by s16_on_pwm_overflow instead.) */
	if (t->wgm_op_mode_kind != avr_timer_wgm_fast_pwm
	    || !(avr->data[t->cs[0].reg] & s16_cs_mask(t)) || !t->tov_cycles
	    || avr_cycle_timer_status(avr, s16_ocr_latch, t)) {
		return;
	}
	/* One cycle before the overflow: the restart then takes the overflow's
	 * place (at the overflow itself simavr's own overflow timer and this
	 * one race, and a period may lose its compare). */
	avr_cycle_count_t end = t->tov_base + t->tov_cycles - 1;
	avr_cycle_timer_register(avr, end > avr->cycle ? end - avr->cycle : 1, s16_ocr_latch, t);
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
static void s16_on_pwm_overflow(struct avr_irq_t *irq, uint32_t value, void *param)
{
	s16_pwm_timer_t *pw = param;
	board_model_t *bm = pw->bm;
	avr_t *avr = bm->avr;
	avr_timer_t *t = pw->timer;

	(void)irq;
	if (!value || t->wgm_op_mode_kind != avr_timer_wgm_pwm || !t->tov_cycles) {
		return;
	}
	avr_cycle_timer_slot_p slot = s16_event_slot(avr, t);

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
			board_model_port_update(oc->port, when);
			oc->latch = com != 2;	/* the match */
			board_model_port_update(oc->port, when + cc);
		}
	}
}

static void s16_watch_pwm(board_model_t *bm, avr_timer_t *t)
{
	for (int i = 0; i < bm->s16.npwm; i++) {
		if (bm->s16.pwm[i].timer == t) {
			return;
		}
	}
	if (bm->s16.npwm == (int)(sizeof(bm->s16.pwm) / sizeof(bm->s16.pwm[0])) || !t->overflow.vector) {
		return;
	}
	s16_pwm_timer_t *pw = &bm->s16.pwm[bm->s16.npwm++];

	pw->bm = bm;
	pw->timer = t;
	avr_irq_register_notify(t->overflow.irq + AVR_INT_IRQ_PENDING, s16_on_pwm_overflow, pw);
}

static void s16_hook_ocr(board_model_t *bm, avr_timer_t *t, uint16_t addr)
{
	if (!addr || !t->r_tcnth) {
		return;	/* 16-bit timers only (the motor PWM) */
	}
	for (int i = 0; i < bm->s16.nocr; i++) {
		if (bm->s16.ocr[i].addr == addr) {
			return;
		}
	}
	if (bm->s16.nocr == BM_MAX_OC) {
		return;
	}
	s16_ocr_hook_t *h = &bm->s16.ocr[bm->s16.nocr++];

	h->bm = bm;
	h->timer = t;
	h->addr = addr;
	io_hook_chain(bm->avr, addr, NULL, s16_on_ocr_write, h, &h->prev);
}

/*
 * Writing TIFR / ETIFR: a 1 clears that flag, a 0 leaves it. simavr 1.6
 * clears every timer flag that is set whatever the value (docs/simulator.md),
 * so one flag cleared before enabling an interrupt would drop another
 * counter's pending compare. The board model owns these registers.
 */
static void s16_on_flag_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	s16_flag_reg_t *r = param;

	(void)addr;
	for (int i = 0; i < r->n; i++) {
		avr_int_vector_t *vec = r->vec[i];
		uint8_t m = (uint8_t)(vec->raised.mask << vec->raised.bit);

		if ((v & m) && avr_regbit_get(avr, vec->raised)) {
			avr_clear_interrupt(avr, vec);
		}
	}
}

static void s16_add_flag(board_model_t *bm, avr_int_vector_t *vec)
{
	s16_flag_reg_t *r = NULL;

	if (!vec->vector || !vec->raised.reg) {
		return;
	}
	for (int i = 0; i < bm->s16.nflag_regs; i++) {
		if (bm->s16.flag_regs[i].addr == vec->raised.reg) {
			r = &bm->s16.flag_regs[i];
		}
	}
	if (!r) {
		if (bm->s16.nflag_regs == (int)(sizeof(bm->s16.flag_regs) / sizeof(bm->s16.flag_regs[0]))) {
			return;
		}
		r = &bm->s16.flag_regs[bm->s16.nflag_regs++];
		r->addr = vec->raised.reg;
		/* replaced, not chained: simavr's own handler is the bug */
		io_hook_prev_t simavrs;
		io_hook_chain(bm->avr, r->addr, NULL, s16_on_flag_write, r, &simavrs);
	}
	if (r->n < S16_MAX_FLAGS) {
		r->vec[r->n++] = vec;
	}
}

static void s16_own_timer_flags(board_model_t *bm)
{
	for (avr_io_t *io = bm->avr->io_port; io; io = io->next) {
		if (!io->kind || strcmp(io->kind, "timer") != 0) {
			continue;
		}
		avr_timer_t *t = (avr_timer_t *)io;

		s16_add_flag(bm, &t->overflow);
		s16_add_flag(bm, &t->icr);
		for (int c = 0; c < AVR_TIMER_COMP_COUNT; c++) {
			s16_add_flag(bm, &t->comp[c].interrupt);
		}
	}
}

/*
 * A forced compare (FOCnx written 1): in normal and CTC modes the unit acts
 * on its pin as on a match (toggle, clear, set by its COM bits), with no
 * interrupt flag; in PWM modes the strobe does nothing. The FOC bits read 0.
 */
static void s16_on_foc_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	s16_foc_hook_t *h = param;
	uint8_t strobes = 0;

	for (int i = 0; i < h->n; i++) {
		strobes |= (uint8_t)(1u << h->bit[i]);
	}
	io_hook_pass_write(avr, &h->prev, addr, (uint8_t)(v & ~strobes));
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
		board_model_port_update(oc->port, avr->cycle);
	}
}

static void s16_hook_foc(board_model_t *bm, const sim_mcu_t *mcu)
{
	for (int f = 0; f < mcu->foc_count; f++) {
		const sim_mcu_foc_t *d = &mcu->foc[f];
		bm_oc_t *oc = NULL;
		s16_foc_hook_t *h = NULL;

		for (int i = 0; i < bm->noc; i++) {
			if (bm->oc[i].timer->name == d->timer && bm->oc[i].comp == d->comp) {
				oc = &bm->oc[i];
			}
		}
		if (!oc) {
			continue;	/* no pin on this board's MCU */
		}
		for (int i = 0; i < bm->s16.nfoc; i++) {
			if (bm->s16.foc[i].addr == d->reg) {
				h = &bm->s16.foc[i];
			}
		}
		if (!h) {
			h = &bm->s16.foc[bm->s16.nfoc++];
			h->bm = bm;
			h->addr = d->reg;
			io_hook_chain(bm->avr, d->reg, NULL, s16_on_foc_write, h, &h->prev);
		}
		if (h->n < 3) {
			h->oc[h->n] = oc;
			h->bit[h->n] = d->bit;
			h->n++;
		}
	}
}


void simavr16_timers_init(board_model_t *bm, const sim_mcu_t *mcu)
{
	for (int i = 0; i < bm->noc; i++) {
		s16_hook_ocr(bm, bm->oc[i].timer, bm->oc[i].timer->comp[bm->oc[i].comp].r_ocr);
		s16_watch_pwm(bm, bm->oc[i].timer);
	}
	s16_own_timer_flags(bm);
	s16_hook_foc(bm, mcu);
	simavr16_no_strict_level(bm->avr);
}
