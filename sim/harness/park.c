/*
 * park.c: parked boards (park.h). A watched turn runs instruction by
 * instruction as avr_step_until() runs it (simavr's avr_run_one(), then
 * avr_step_after()), each instruction first decoded here and the watch given
 * up unless it is one a parked loop may hold: watching changes nothing in
 * how the board runs.
 */
#include <string.h>

#include "harness/park.h"

#include "sim_core.h"

#include "harness/avr_step.h"
#include "harness/park_op.h"

#define PARK_BACKOFF_MIN 16
#define PARK_BACKOFF_MAX 128

/* --- the board's state at a boundary ----------------------------------------- */

static void park_save(park_point_t *pt, const avr_t *avr, uint64_t start)
{
	pt->pc = avr->pc;
	pt->off = (uint32_t)(avr->cycle - start);
	memcpy(pt->regs, avr->data, sizeof(pt->regs));
	memcpy(pt->io, avr->data + R_SPL, sizeof(pt->io));
	memcpy(pt->sreg, avr->sreg, sizeof(pt->sreg));
}

static void park_load(const park_point_t *pt, avr_t *avr)
{
	avr->pc = pt->pc;
	memcpy(avr->data, pt->regs, sizeof(pt->regs));
	memcpy(avr->data + R_SPL, pt->io, sizeof(pt->io));
	memcpy(avr->sreg, pt->sreg, sizeof(pt->sreg));
}

static int park_same_point(const park_point_t *a, const park_point_t *b)
{
	return a->pc == b->pc && !memcmp(a->regs, b->regs, sizeof(a->regs)) &&
	       !memcmp(a->io, b->io, sizeof(a->io)) && !memcmp(a->sreg, b->sreg, sizeof(a->sreg));
}

static int park_head(park_t *p, const avr_t *avr);

/* --- the cycle timers --------------------------------------------------------- */

typedef struct park_timers_t {
	avr_cycle_timer_t fn[MAX_CYCLE_TIMERS];
	void *param[MAX_CYCLE_TIMERS];
	uint64_t when[MAX_CYCLE_TIMERS];
	int n;
} park_timers_t;

static void park_timers(park_timers_t *t, const avr_t *avr)
{
	t->n = 0;
	for (const avr_cycle_timer_slot_t *s = avr->cycle_timers.timer;
	     s && t->n < MAX_CYCLE_TIMERS; s = s->next) {
		t->fn[t->n] = s->timer;
		t->param[t->n] = s->param;
		t->when[t->n] = s->when;
		t->n++;
	}
}

static int park_find(const park_timers_t *t, avr_cycle_timer_t fn, void *param)
{
	for (int i = 0; i < t->n; i++) {
		if (t->fn[i] == fn && t->param[i] == param) {
			return i;
		}
	}
	return -1;
}

/* The loop's WDR, begun at cycle AT, has run: the timer it moved (the
 * watchdog's, if it runs) and its period. 0 if it moved more than one. */
static int park_wdr_ran(park_t *p, const avr_t *avr, const park_timers_t *before, uint64_t at)
{
	park_timers_t now;
	int moved = -1;

	park_timers(&now, avr);
	for (int i = 0; i < now.n; i++) {
		int k = park_find(before, now.fn[i], now.param[i]);

		if (k < 0 || now.when[i] != before->when[k]) {
			if (moved >= 0) {
				return 0;
			}
			moved = i;
		}
	}
	p->wd_fn = NULL;
	if (moved >= 0) {
		p->wd_fn = now.fn[moved];
		p->wd_param = now.param[moved];
		p->wd_period = now.when[moved] - at;
	}
	return 1;
}

/* --- watching for a loop ------------------------------------------------------- */

/* The loop reads the I/O register at A: its value is watched. */
static int park_note_io(park_t *p, const avr_t *avr, uint16_t a)
{
	for (int k = 0; k < p->nio; k++) {
		if (p->io_addr[k] == a) {
			return avr->data[a] == p->io_val[k];
		}
	}
	if (p->nio == PARK_MAX_IO) {
		return 0;
	}
	p->io_addr[p->nio] = a;
	p->io_val[p->nio] = avr->data[a];
	p->nio++;
	return 1;
}

/* Can a watch begin where AVR stands? */
static int park_can_watch(const avr_t *avr)
{
	if (avr->state != cpu_Running || avr->interrupt_state || !avr->sreg[S_I] ||
	    avr->address_size != 2 || avr->run != avr_callback_run_raw || avr->gdb ||
	    !park_plain(avr, park_sp(avr) - 1u)) {
		return 0;
	}
	/* SP lives in plain cells: push, pop, call and return change nothing else */
	for (uint16_t a = R_SPL; a <= R_SPH; a++) {
		const avr_io_addr_t io = AVR_DATA_TO_IO(a);

		if (avr->io[io].w.c || avr->io[io].irq) {
			return 0;
		}
	}
	return 1;
}

/* The watch failed: try again later (FAR: after the backoff). */
static void park_unwatch(park_t *p, const avr_t *avr, int far)
{
	p->watching = 0;
	if (!far) {
		return;
	}
	p->retry_at = avr->cycle + p->backoff;
	if (p->backoff < PARK_BACKOFF_MAX) {
		p->backoff *= 2;
	}
}

/* A whole turn was watched and the board is back where it began: park it
 * here if the turn repeats. 1 if parked. */
static int park_settle(park_t *p, avr_t *avr)
{
	int n = p->wn;

	if (!park_same_point(&p->pt[n], &p->pt[0]) || park_io_moved(p, avr)) {
		return 0;
	}
	p->n = n;
	p->len = p->pt[n].off;
	if (p->wdr >= 0 && !p->wd_fn) {
		p->wdr = -1;		/* a WDR with the watchdog off: nothing moves */
	}
	if (p->wdr >= 0) {
		const avr_cycle_timer_slot_t *s = avr->cycle_timers.timer;

		while (s && !(s->timer == p->wd_fn && s->param == p->wd_param)) {
			s = s->next;
		}
		if (!s) {
			return 0;
		}
		p->wd_before = s->when;
	}
	if (!park_head(p, avr) || (p->wdr >= 0 && p->wd_before <= p->limit)) {
		return 0;
	}
	for (int k = 0; k <= n; k++) {
		p->off[k] = (uint16_t)p->pt[k].off;
	}
	for (uint32_t d = 0, k = 0; d <= p->len; d++) {
		while (p->off[k] < d) {
			k++;
		}
		p->next[d] = (uint8_t)k;
		p->adv[d] = p->off[k];
	}
	p->first = p->start = avr->cycle;
	p->j = 0;
	p->parked = 1;
	p->backoff = PARK_BACKOFF_MIN;
	return 1;
}

/* The SRAM cells the instruction reads and changes. A cell the turn
 * changes before it ever reads it (the stack an interrupt used, written
 * again by a call) does not make the turn's start differ from its end in
 * anything the turn depends on; a cell read and then changed does
 * (P->dirty). */
static void park_note_cells(park_t *p, const park_op_t *o)
{
	for (int k = 0; k < o->nst; k++) {
		int read = p->nread == PARK_MAX_READS;

		for (int i = 0; i < p->nread && !read; i++) {
			read = p->read[i] == o->st[k];
		}
		p->dirty |= read;
	}
	for (int k = 0; k < o->nld; k++) {
		if (p->nread < PARK_MAX_READS) {
			p->read[p->nread++] = o->ld[k];
		}
	}
}

/* A watch of a turn begins where AVR stands. */
static void park_watch_from(park_t *p, const avr_t *avr)
{
	p->watching = 1;
	p->dirty = 0;
	p->nread = 0;
	p->wn = 0;
	p->nio = 0;
	p->wdr = -1;
	p->wd_fn = NULL;
	p->first = avr->cycle;
	park_save(&p->pt[0], avr, p->first);
}

/* One instruction watched (as avr_step_until runs it). 1 while the watch
 * goes on, 0 when it ended (parked, or given up). */
static int park_watch_one(park_t *p, avr_t *avr)
{
	park_op_t o = { .nld = 0, .nst = 0 };
	park_timers_t before;
	uint64_t at = avr->cycle;
	avr_flashaddr_t new_pc;

	before.n = 0;

	if (p->wn == PARK_MAX_STEPS || !park_op_ok(avr, avr->pc, &o) || (o.wdr && p->wdr >= 0) ||
	    (o.io && !park_note_io(p, avr, o.io))) {
		park_unwatch(p, avr, 1);
		return 0;
	}
	if (o.wdr) {
		p->wdr = p->wn;
		park_timers(&before, avr);
	}
	park_note_cells(p, &o);
	new_pc = avr_run_one(avr);
	avr_step_after(avr, new_pc);
	if (avr->state != cpu_Running || avr->interrupt_state || avr->pc != new_pc) {
		park_unwatch(p, avr, 0);	/* an interrupt: watch again after it */
		return 0;
	}
	if ((o.wdr && !park_wdr_ran(p, avr, &before, at)) || avr->cycle - p->first > PARK_MAX_CYCLES) {
		park_unwatch(p, avr, 1);
		return 0;
	}
	park_save(&p->pt[++p->wn], avr, p->first);
	if (avr->pc != p->pt[0].pc) {
		return 1;
	}
	if (p->dirty && !p->warm && park_same_point(&p->pt[p->wn], &p->pt[0])) {
		/* a store changed SRAM (the stack an interrupt used): the next
		 * turn, once, may be the loop's */
		p->warm = 1;
		park_watch_from(p, avr);
		return 1;
	}
	p->watching = 0;
	if (p->dirty || !park_settle(p, avr)) {
		park_unwatch(p, avr, 1);
	}
	return 0;
}

int park_run(park_t *p, avr_t *avr, uint64_t end, int allow)
{
	if (!allow) {
		p->watching = 0;	/* one begun before parking was refused (profiling) */
	}
	while (p->watching && avr->cycle < end) {
		if (!park_watch_one(p, avr) && p->parked) {
			if (park_stays(p, avr, end)) {
				return avr->state;
			}
			break;		/* left again at once: run normally */
		}
	}
	avr_step_until(avr, end);
	if (allow && !p->watching && avr->cycle >= p->retry_at && park_can_watch(avr)) {
		if (!p->backoff) {
			p->backoff = PARK_BACKOFF_MIN;
		}
		p->warm = 0;
		park_watch_from(p, avr);
	}
	return avr->state;
}

/* The watchdog timer where the last WDR has put it (the turn at P->start,
 * boundary P->j): the loop's, once it has run one since the board was
 * parked, else the one before, where the timer was then. */
static void park_wd(const park_t *p, avr_t *avr)
{
	uint64_t when = p->wd_before;

	if (p->start > p->first || p->j > p->wdr) {
		when = (p->j > p->wdr ? p->start : p->start - p->len) + p->off[p->wdr] + p->wd_period;
	}

	avr_cycle_timer_register(avr, when - avr->cycle, p->wd_fn, p->wd_param);
}

/* The first timer, one the loop leaves alone: due first. 0 if not so. */
static int park_head(park_t *p, const avr_t *avr)
{
	const avr_cycle_timer_slot_t *h = avr->cycle_timers.timer;

	if (!h || (p->wdr >= 0 && h->timer == p->wd_fn && h->param == p->wd_param)) {
		return 0;
	}
	p->head = h;
	p->head_when = h->when;
	p->limit = h->when;
	return 1;
}

/* The boundary at or past cycle CYC, which is past where the board stands. */
static void park_seek(const park_t *p, uint64_t cyc, uint64_t *start, int *j)
{
	uint64_t s = p->start, d = cyc - s;
	int k;

	if (d > p->len) {
		uint64_t turns = (d - 1) / p->len;

		s += turns * p->len;
		d -= turns * p->len;
	}
	k = p->next[d];
	if (k == p->n) {
		s += p->len;
		k = 0;
	}
	*start = s;
	*j = k;
}

/* The board put at boundary P->j of the turn at P->start: its state, its
 * cycle, and the watchdog timer where the loop's WDR left it. */
static void park_put(const park_t *p, avr_t *avr)
{
	const park_point_t *pt = &p->pt[p->j];

	park_load(pt, avr);
	avr->cycle = p->start + pt->off;
	if (p->wdr >= 0) {
		park_wd(p, avr);
	}
}

/* A timer falls due at boundary J of the turn at START: the board is put
 * there as the instruction ending there left it, and what avr_run() does
 * after an instruction is done. 1 when it stays parked: no interrupt, the
 * loop's PC, and the next timer again one the loop leaves alone. */
static int park_fire(park_t *p, avr_t *avr, uint64_t start, int j)
{
	const park_point_t *pt = &p->pt[j];

	p->start = start;
	p->j = j;
	park_put(p, avr);
	avr->pc = p->pt[j ? j - 1 : p->n - 1].pc;	/* as avr_run_one() left it */
	avr_step_after(avr, pt->pc);
	if (avr->state != cpu_Running || avr->interrupt_state || avr->pc != pt->pc ||
	    park_io_moved(p, avr) || !park_head(p, avr)) {
		p->parked = 0;
		p->retry_at = 0;
		return 0;
	}
	return 1;
}

/* P->j for where the board stands (park_stays moves only its cycle). */
static void park_where(park_t *p, const avr_t *avr)
{
	uint64_t d = avr->cycle - p->start;

	if (d >= p->len) {
		p->start += p->len;
		d -= p->len;
	}
	p->j = p->next[d];
}

int park_advance(park_t *p, avr_t *avr, uint64_t end)
{
	park_where(p, avr);
	if (avr->interrupt_state || avr->state != cpu_Running ||
	    avr->cycle_timers.timer != p->head || p->head->when != p->head_when ||
	    park_io_moved(p, avr)) {
		park_leave(p, avr);
		return 1;
	}
	while (avr->cycle < end) {
		uint64_t start;
		int j;

		park_seek(p, end, &start, &j);
		if (start + p->off[j] < p->limit) {
			p->start = start;
			p->j = j;
			avr->cycle = start + p->off[j];
			return 0;
		}
		park_seek(p, p->limit, &start, &j);
		if (!park_fire(p, avr, start, j)) {
			return 1;
		}
	}
	return 0;
}

void park_leave(park_t *p, avr_t *avr)
{
	park_where(p, avr);
	park_put(p, avr);
	p->parked = 0;
	p->retry_at = 0;
}

