/*
 * isr_watch.c: interrupt handler durations.
 */
#include <string.h>

#include "harness/isr_watch.h"

/* Another vector's handler starts (1) or returns (0). */
static void isr_watch_other(struct avr_irq_t *irq, uint32_t value, void *param)
{
	isr_watch_t *w = param;
	uint64_t now = w->avr->cycle;

	(void)irq;
	if (!w->inside) {
		return;
	}
	if (value) {
		if (w->other_depth++ == 0) {
			w->other_since = now;
		}
	} else if (w->other_depth > 0 && --w->other_depth == 0) {
		w->nested += now - w->other_since;
	}
}

/* Every other vector, once: by the first run all peripherals (simavr's and
 * the simulator's own) have registered theirs. */
static void isr_watch_hook_others(isr_watch_t *w)
{
	avr_int_table_p t = &w->avr->interrupts;

	w->others_hooked = 1;
	for (int i = 0; i < t->vector_count; i++) {
		if (t->vector[i] && t->vector[i] != w->vect) {
			avr_irq_register_notify(&t->vector[i]->irq[AVR_INT_IRQ_RUNNING],
						isr_watch_other, w);
		}
	}
}

static void isr_watch_running(struct avr_irq_t *irq, uint32_t value, void *param)
{
	isr_watch_t *w = param;
	uint64_t now = w->avr->cycle;

	(void)irq;
	if (value) {
		if (!w->others_hooked) {
			isr_watch_hook_others(w);
		}
		w->entered = now;
		w->inside = 1;
		w->other_depth = 0;
		w->nested = 0;
		return;
	}
	if (!w->inside) {
		return;
	}
	w->inside = 0;
	uint64_t took = now - w->entered - w->nested;
	if (took > w->longest) {
		w->longest = took;
	}
	w->count++;
	w->total += took;
}

void isr_watch_init(isr_watch_t *w, avr_t *avr, avr_int_vector_t *vect)
{
	memset(w, 0, sizeof(*w));
	w->avr = avr;
	w->vect = vect;
	avr_irq_register_notify(&vect->irq[AVR_INT_IRQ_RUNNING], isr_watch_running, w);
}

void isr_watch_clear(isr_watch_t *w)
{
	w->longest = 0;
	w->count = 0;
	w->total = 0;
}

static void flag_watch_pending(struct avr_irq_t *irq, uint32_t value, void *param)
{
	flag_watch_t *w = param;
	uint64_t now = w->avr->cycle;

	(void)irq;
	if (value) {
		/* simavr tells of a raise only when the flag was down: one while
		 * it is held raised here was cleared unseen (a reset clears the
		 * flags without telling), so it counts from now */
		w->raised = 1;
		w->since = now;
		return;
	}
	if (!w->raised) {
		return;
	}
	w->raised = 0;
	if (now - w->since > w->longest) {
		w->longest = now - w->since;
	}
	w->count++;
}

int flag_watch_init(flag_watch_t *w, avr_t *avr, int vector)
{
	avr_int_table_p t = &avr->interrupts;

	memset(w, 0, sizeof(*w));
	w->avr = avr;
	w->vector = vector;
	for (int i = 0; i < t->vector_count; i++) {
		if (t->vector[i] && t->vector[i]->vector == vector) {
			avr_irq_register_notify(&t->vector[i]->irq[AVR_INT_IRQ_PENDING],
						flag_watch_pending, w);
			return 0;
		}
	}
	return -1;
}

void flag_watch_clear(flag_watch_t *w)
{
	w->longest = 0;
	w->count = 0;
}
