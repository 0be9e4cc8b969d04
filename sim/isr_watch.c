/*
 * isr_watch.c: interrupt handler durations.
 */
#include <string.h>

#include "isr_watch.h"

static void isr_watch_running(struct avr_irq_t *irq, uint32_t value, void *param)
{
	isr_watch_t *w = param;
	uint64_t now = w->avr->cycle;

	(void)irq;
	if (value) {
		w->entered = now;
		w->inside = 1;
		return;
	}
	if (!w->inside) {
		return;
	}
	w->inside = 0;
	uint64_t took = now - w->entered;
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
	avr_irq_register_notify(&vect->irq[AVR_INT_IRQ_RUNNING], isr_watch_running, w);
}

void isr_watch_clear(isr_watch_t *w)
{
	w->longest = 0;
	w->count = 0;
	w->total = 0;
}
