/*
 * cd4017.h: CD4017 decade counter with ten decoded outputs. RESET high
 * forces Q0 at once and holds it; each rising CLOCK edge while RESET is low
 * advances Q0 -> Q1 -> ... -> Q9 -> Q0 (CLOCK ENABLE tied low). Output edges
 * carry the cycle of the input edge that caused them. Power-up state: Q0.
 */
#ifndef SIM_PARTS_CD4017_H
#define SIM_PARTS_CD4017_H

#include "harness/signals.h"

typedef struct cd4017_t {
	signal_t q[10];			/* "<name>q0".."<name>q9" */
	int state;			/* the output that is high */
	int clock, reset;		/* input levels */
} cd4017_t;

/* Register the outputs as signals NAMEq0..NAMEq9. 0 or -1. */
int cd4017_init(cd4017_t *c, signals_t *set, const char *name);

/* Signal listeners for the clock and reset inputs (param = the counter). */
void cd4017_on_clock(void *param, signal_t *s, uint64_t cycle, int level);
void cd4017_on_reset(void *param, signal_t *s, uint64_t cycle, int level);

#endif
