/*
 * The M32-D servo schedule: which edge (a channel's rise or fall) comes how
 * many cycles after the one before, in every 20 ms frame. servo_plan()
 * builds it in the main loop when widths change; the Timer2 compare
 * interrupt in servo_pins.c only runs it. No hardware in here, so the host
 * unit tests run the planner as the firmware does (tests/unit).
 *
 * Channel n's pulse starts about SERVO_SLOT * n cycles into the frame, so
 * at most a few pulses overlap. Where an edge would come within SERVO_GAP
 * cycles of another channel's edge, the planner moves that channel's whole
 * pulse by whole SERVO_SHIFTs (its width and period stay exact): the
 * interrupt needs that much time between two edges to make each at its
 * cycle.
 */
#ifndef SERVO_PLAN_H
#define SERVO_PLAN_H

#include <stdint.h>

#include "drivers/drv_servo.h"

#define SERVO_FRAME  147456UL  /* 20 ms at 7.3728 MHz */
#define SERVO_SLOT   8191UL    /* between channel starts: 1.111 ms */
#define SERVO_GAP    400       /* least distance between two edges, cycles */
#define SERVO_SHIFT  32        /* unit of a channel's move, cycles */
#define SERVO_MOVES  96        /* most units a channel moves either way */
#define SERVO_EDGES  (2 * SERVO_CHANNELS)
#define SERVO_FALL   0x80      /* edge code: channel | SERVO_FALL | SERVO_LONG */
#define SERVO_LONG   0x40      /* the edge's delta is 65536 cycles more */
#define SERVO_CHAN   0x1F      /* the edge code's channel */

typedef struct {
	uint8_t n;                        /* edges in this frame */
	uint8_t edge[SERVO_EDGES];        /* sorted by time */
	uint16_t delta[SERVO_EDGES];      /* cycles after the edge before (the
					   * first: after the frame's start),
					   * + 65536 with SERVO_LONG */
} servo_sched_t;

/* Plans channel widths in microseconds (0 = off, else 500..2500) into `s`
 * from `last`, the schedule planned before (empty at first; it may be `s`
 * itself). A channel whose width is the same as before stays where it was;
 * the others are placed in channel order, each at the nearest place clear
 * of those placed before it. */
void servo_plan(servo_sched_t *s, const servo_sched_t *last, const uint16_t *widths_us);

#endif
