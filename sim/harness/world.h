/*
 * world.h: everything the simulated boards share: the boards themselves
 * (board 0 is the gateway, whose serial port reaches the PC), the one I2C
 * bus with its parts (part.h) and every board's TWI, the trace, and
 * simulated time.
 *
 * Time: every board counts the same cycles (all start at 0, all run at
 * SIM_FREQUENCY). world_run() steps the boards in lock-step: in each
 * quantum of WORLD_QUANTUM cycles every board runs, in board order, until
 * its cycle reaches the quantum's end. Anything one board does to another
 * (through the bus) is stamped with its own cycle, so the order inside a
 * quantum costs at most one quantum of error, and the fixed board order
 * keeps runs deterministic.
 */
#ifndef SIM_WORLD_H
#define SIM_WORLD_H

#include <stdint.h>

#include "boards/sim_board.h"
#include "harness/park.h"
#include "harness/trace.h"
#include "periph/twi_bus.h"
#include "parts/part.h"

/* One quantum: at most a quarter of the shortest SCL period the TWI can
 * make (16 + 2*TWBR*4^TWPS = 18 cycles at TWBR=1, TWPS=0, i.e. 400 kHz
 * and above), so a board sees another's bus event at most 4 cycles late. */
#define WORLD_QUANTUM 4

#define WORLD_MAX_BOARDS 16

typedef struct world_t {
	sim_board_t *boards[WORLD_MAX_BOARDS];	/* [0]: the gateway */
	int nboards;
	twi_bus_t bus;
	part_list_t parts;		/* the parts on the bus (part.h) */
	trace_t trace;
	uint64_t now;			/* every board has reached this cycle */
	int dead;			/* index of a board that crashed or stopped, -1 */
	int dead_state;
	park_t park[WORLD_MAX_BOARDS];	/* boards idling in a loop (park.h) */
	int no_park;			/* run every board every quantum */
} world_t;

/* An empty world: no boards, a bus traced to TRACE (opened by the caller). */
void world_init(world_t *w);

/* Make a part of KIND (an I2C kind) at ADDR8 from OPTS and put it on the
 * bus. NULL, or the text why not. */
const char *world_add_part(world_t *w, const part_kind_t *kind, uint8_t addr8, const char *opts);

/* Run every board up to cycle TARGET, or, with BYTES > 0, until the end of
 * the quantum in which the bus's master has clocked BYTES more bytes
 * (twi_bus_t.bytes; a control client's `wait i2c`), if that comes first:
 * the boards idling meanwhile stay parked. 0, or 1 when a board's firmware
 * crashed or stopped for good (w->dead says which). */
int world_run(world_t *w, uint64_t target, uint32_t bytes);

/* The gateway's cycle: world time for the control interface. */
static inline uint64_t world_cycle(const world_t *w)
{
	return w->boards[0]->avr->cycle;
}

/* Sum of every board's and the bus's activity counters. */
uint32_t world_activity(const world_t *w);

#endif
