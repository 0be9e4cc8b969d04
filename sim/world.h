/*
 * world.h: everything the simulated boards share: the boards themselves
 * (board 0 is the gateway, whose serial port reaches the PC), the one I2C
 * bus with its devices (EEPROMs, and every board's TWI), the trace, and
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

#include "sim_board.h"
#include "trace.h"
#include "twi_bus.h"
#include "parts/eeprom24.h"
#include "parts/srf08.h"

/* One quantum: at most a quarter of the shortest SCL period the TWI can
 * make (16 + 2*TWBR*4^TWPS = 18 cycles at TWBR=1, TWPS=0, i.e. 400 kHz
 * and above), so a board sees another's bus event at most 4 cycles late. */
#define WORLD_QUANTUM 4

#define WORLD_MAX_BOARDS 16
#define WORLD_MAX_EEPROMS 8
#define WORLD_MAX_SRF08 16	/* as many as it has addresses */

typedef struct world_t {
	sim_board_t *boards[WORLD_MAX_BOARDS];	/* [0]: the gateway */
	int nboards;
	twi_bus_t bus;
	eeprom24_t eeprom[WORLD_MAX_EEPROMS];
	int neeprom;
	srf08_t srf08[WORLD_MAX_SRF08];
	int nsrf08;
	trace_t trace;
	uint64_t now;			/* every board has reached this cycle */
	int dead;			/* index of a board that crashed or stopped, -1 */
	int dead_state;
} world_t;

/* An empty world: no boards, a bus traced to TRACE (opened by the caller). */
void world_init(world_t *w);

/* Add an EEPROM (24C02-like) at ADDR8; WP ties its write-protect pin high. */
void world_add_eeprom(world_t *w, uint8_t addr8, int wp);

/* Add an SRF08 ranger at ADDR8 (0xE0..0xFE, even). */
void world_add_srf08(world_t *w, uint8_t addr8);

/* Run every board up to cycle TARGET. 0, or 1 when a board's firmware
 * crashed or stopped for good (w->dead says which). */
int world_run(world_t *w, uint64_t target);

/* The gateway's cycle: world time for the control interface. */
static inline uint64_t world_cycle(const world_t *w)
{
	return w->boards[0]->avr->cycle;
}

/* Sum of every board's and the bus's activity counters. */
uint32_t world_activity(const world_t *w);

#endif
