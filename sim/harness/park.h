/*
 * park.h: a board idling in a loop is not run, it is parked: its place in
 * the loop follows world time, exactly (docs/simulator.md, "Parked boards").
 *
 * A board is parked once one turn of the loop it is in has been watched
 * (run normally, each instruction decoded first) and found to repeat:
 * every instruction only reads registers, SRAM, flash, SREG and I/O
 * registers that have no read handler (TWCR, UCSRA: their values are then
 * watched), stores only to SRAM, and no SRAM cell it reads changes; no
 * interrupt comes, none is enabled or disabled; the turn ends at the same
 * PC with the same registers, stack pointer and SREG. Each turn is then the
 * same instructions with the same cycle counts, until something from
 * outside the loop happens. Parked, the board moves from one instruction
 * boundary of the recorded turn to the next as world time passes, and its
 * cycle is the one lock-step gives it, so the bus and the other boards see
 * it where they always did. When one of its cycle timers falls due, the
 * board is put on the boundary where simavr would run it and the timers run
 * as avr_run() runs them; it stays parked unless that raised an interrupt
 * or changed a watched register. It leaves the loop, at the boundary where
 * it stands (registers, SREG, stack pointer, PC of that boundary put back,
 * and the watchdog timer that the loop's WDR moves set where the last WDR
 * put it), and runs normally when an interrupt is pending, its first cycle
 * timer is not the one it was (set or cancelled from outside), a watched
 * register changed, and at the end of every world_run().
 */
#ifndef SIM_PARK_H
#define SIM_PARK_H

#include <stdint.h>

#include "sim_avr.h"

#define PARK_MAX_STEPS 96	/* instructions in a loop's turn */
#define PARK_MAX_CYCLES 256	/* its cycles */
#define PARK_MAX_IO 4		/* I/O registers it reads */
#define PARK_MAX_READS 64	/* SRAM reads it makes (followed) */

/* The board at an instruction boundary of the turn. */
typedef struct park_point_t {
	avr_flashaddr_t pc;
	uint32_t off;			/* cycles from the turn's start */
	uint8_t regs[32];		/* r0..r31 */
	uint8_t io[3];			/* SPL, SPH and the SREG cell */
	uint8_t sreg[8];		/* simavr's SREG bits */
} park_point_t;

typedef struct park_t {
	/* where the parked board stands (read every quantum: kept together) */
	int parked;
	int j;				/* boundary: before instruction j (park_where) */
	uint64_t start;			/* the current turn's start */
	uint64_t limit;			/* the first cycle timer's due cycle */
	const avr_cycle_timer_slot_t *head;	/* the timer list's head then */
	uint64_t head_when;
	uint32_t len;			/* the turn's cycles */
	int n;				/* its instructions */
	uint16_t off[PARK_MAX_STEPS + 1];	/* boundary j: cycles from the turn's start */
	uint16_t adv[PARK_MAX_CYCLES + 1];	/* cycle d of the turn: the first boundary's off[] at or past it */
	uint8_t next[PARK_MAX_CYCLES + 1];	/* ... and its index (n: the next turn's 0) */
	int nio;			/* I/O registers the loop reads, */
	uint16_t io_addr[PARK_MAX_IO];	/* their data addresses */
	uint8_t io_val[PARK_MAX_IO];	/* and the values it read */

	/* the turn */
	int wdr;			/* index of its WDR, -1: none (or no watchdog) */
	avr_cycle_timer_t wd_fn;	/* the timer the WDR moves */
	void *wd_param;
	uint64_t wd_before;		/* its due cycle when the board was parked */
	uint64_t wd_period;		/* a WDR at cycle c sets it due at c + this */
	uint64_t first;			/* the watched turn's start, then where it was parked */
	park_point_t pt[PARK_MAX_STEPS + 1];

	int watching;			/* a turn is being watched: pt[0..wn] so far */
	int wn;
	int dirty;			/* it changed an SRAM cell it had read */
	uint16_t read[PARK_MAX_READS];	/* the SRAM cells it read */
	int nread;
	int warm;			/* the watch began again after such a turn */
	uint64_t retry_at;		/* no new watch before this cycle */
	uint32_t backoff;		/* cycles to the next watch after a failed one */
} park_t;

/* Run a board that is not parked to END (as avr_step_until), watching a
 * turn of the loop it is in when a watch is on, and parking it when the
 * turn repeats; with ALLOW, a watch begins at the end when one is due;
 * without it, a watch under way ends (no parking: `profile`).
 * Returns the MCU's state. */
int park_run(park_t *p, avr_t *avr, uint64_t end, int allow);

/* A parked board's turn in the lock-step, to quantum END: 0 when it stays
 * parked (its cycle the first boundary at or past END), 1 when it left the
 * loop: the caller runs it normally to END. */
int park_advance(park_t *p, avr_t *avr, uint64_t end);

/* Has an I/O register the loop reads changed? */
static inline int park_io_moved(const park_t *p, const avr_t *avr)
{
	for (int k = 0; k < p->nio; k++) {
		if (avr->data[p->io_addr[k]] != p->io_val[k]) {
			return 1;
		}
	}
	return 0;
}

/* A parked board with nothing from outside: no interrupt pending, its
 * first timer the one it was, the watched registers as the loop read them. */
static inline int park_quiet(const park_t *p, const avr_t *avr)
{
	return p->parked && !avr->interrupt_state && avr->state == cpu_Running &&
	       avr->cycle_timers.timer == p->head && p->head->when == p->head_when &&
	       !park_io_moved(p, avr);
}

/* park_advance(), 0 or 1 the other way round, with its common case
 * inline: nothing from outside, no timer due before the boundary. */
static inline int park_stays(park_t *p, avr_t *avr, uint64_t end)
{
	uint64_t start = p->start, d = end - start, at;

	if (avr->interrupt_state || avr->cycle_timers.timer != p->head ||
	    p->head->when != p->head_when || avr->cycle >= end || d > 2 * (uint64_t)p->len ||
	    park_io_moved(p, avr)) {
		return !park_advance(p, avr, end);
	}
	if (d > p->len) {
		start += p->len;
		d -= p->len;
	}
	at = start + p->adv[d];
	if (at >= p->limit) {
		return !park_advance(p, avr, end);
	}
	p->start = start;	/* p->j follows from the cycle (park_where) */
	avr->cycle = at;
	return 1;
}

/* A parked board leaves the loop where it stands. */
void park_leave(park_t *p, avr_t *avr);

#endif
