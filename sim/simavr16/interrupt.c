/*
 * interrupt.c: a repair of simavr 1.6's interrupt queue (interrupt.h).
 */
#include "simavr16/interrupt.h"

/* simavr 1.6's avr_clear_interrupt leaves the vector's entry in its queue
 * of pending interrupts. A firmware that clears a flag with its interrupt
 * masked (the M32-D's servo interrupt empties UDR so) would add an entry
 * at every raise while the queue serves one per interrupt taken: the
 * 64-entry queue fills, a later raise finds no room, and the vector stays
 * flagged pending without ever being taken. Its entries go too. */
void simavr16_withdraw_interrupt(avr_t *avr, avr_int_vector_t *v)
{
	avr_int_pending_t *q = &avr->interrupts.pending;
	unsigned keep = q->read;

	avr_clear_interrupt(avr, v);
	for (unsigned i = q->read; i != q->write; i = (i + 1) & (avr_int_pending_fifo_size - 1)) {
		if (q->buffer[i] != v) {
			q->buffer[keep] = q->buffer[i];
			keep = (keep + 1) & (avr_int_pending_fifo_size - 1);
		}
	}
	q->write = keep;
}
