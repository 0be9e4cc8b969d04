/*
 * The M32-D servo schedule: which edge (a channel's rise or fall) comes at
 * which cycle of every 20 ms frame, in time order. servo_plan()
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
#define SERVO_FALL   0x80      /* edge code: channel | SERVO_FALL | cycle bits 16-17 */
#define SERVO_HI     0x30      /* the edge's cycle in the frame, bits 16 and 17 */
#define SERVO_CHAN   0x0F      /* the edge code's channel */

typedef struct {
	uint8_t code;   /* channel | SERVO_FALL | cycle bits 16-17 (SERVO_HI) */
	uint16_t at;    /* cycle in the frame, bits 0-15 */
} servo_edge_t;

typedef struct {
	uint8_t n;                        /* edges in this frame */
	servo_edge_t edge[SERVO_EDGES];   /* in time order */
} servo_sched_t;

/* An edge's cycle in the frame. (Byte operations: avr-gcc makes a nibble
 * swap of the shift by 4.) */
static inline uint32_t servo_cycle(const servo_edge_t *e)
{
	uint8_t hi = (uint8_t)(e->code >> 4) & 3;
	return (uint32_t)hi << 16 | e->at;
}

/* Plans channel widths in microseconds (0 = off, else 500..2500) into `s`
 * from `last`, the schedule planned before (empty at first; it may be `s`
 * itself). A channel whose width in cycles is the one the last call planned
 * stays where it was (so the widths may change more than once between two
 * plans); the others are placed in channel
 * order, each at the nearest place clear of the channels that stayed and
 * of those placed before it. */
void servo_plan(servo_sched_t *s, const servo_sched_t *last, const uint16_t *widths_us);

#endif
