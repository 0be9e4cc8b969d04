/*
 * isr_watch.h: how long an interrupt handler runs, in cycles, from the
 * moment the CPU takes the vector to its RETI (simavr raises the vector's
 * AVR_INT_IRQ_RUNNING with 1, then 0), less the time of other handlers
 * that interrupt it (a handler that enables interrupts early). Keeps the
 * longest, the count and the total, for `make bench` (the slave's TWI
 * interrupt) and the control request `isr`.
 */
#ifndef SIM_ISR_WATCH_H
#define SIM_ISR_WATCH_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_interrupts.h"

typedef struct isr_watch_t {
	avr_t *avr;
	avr_int_vector_t *vect;
	int others_hooked;	/* the other vectors are watched for nesting */
	uint64_t entered;	/* cycle the running handler was entered at */
	int inside;
	int other_depth;	/* other handlers running inside it */
	uint64_t other_since;
	uint64_t nested;	/* their cycles, during this run */
	uint64_t longest;	/* cycles */
	uint64_t count;
	uint64_t total;
} isr_watch_t;

/* Watch VECT's handler on AVR. */
void isr_watch_init(isr_watch_t *w, avr_t *avr, avr_int_vector_t *vect);

/* Forget what was measured (the counts start again). */
void isr_watch_clear(isr_watch_t *w);

/*
 * How long an interrupt's flag stays raised before its handler takes it or
 * the firmware clears it (a write of 1 to the flag), in cycles: a flag
 * raised again meanwhile is an event lost (a timer overflow a wrap later
 * goes uncounted; simavr 1.6 does not tell of that raise, so the longest
 * time tells: over a wrap). The control request `flag`.
 */
typedef struct flag_watch_t {
	avr_t *avr;
	int vector;
	int raised;
	uint64_t since;		/* cycle it was raised at */
	uint64_t longest;	/* cycles */
	uint64_t count;		/* raises taken or cleared */
} flag_watch_t;

/* Watch vector number VECTOR's flag on AVR: 0, or -1 if it has none. */
int flag_watch_init(flag_watch_t *w, avr_t *avr, int vector);

void flag_watch_clear(flag_watch_t *w);

#endif
