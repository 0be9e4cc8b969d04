/*
 * fault.h: faults and resets the control socket asks for (docs/simulator.md
 * "Faults and resets"): a hung firmware, and resets other than the
 * watchdog's, each leaving the reset flag silicon would leave in MCUCSR.
 */
#ifndef SIM_FAULT_H
#define SIM_FAULT_H

#include "sim_avr.h"

#include "boards/board_model.h"

/* The firmware stops running its program: interrupts off and the PC parked
 * on an endless loop (`rjmp .-2`, which the harness puts in the top flash
 * word, past any firmware). simavr goes on stepping that loop and its
 * cycle timers (the watchdog's) go on too, so the watchdog resets the
 * board as on silicon; a core that slept with interrupts off would end
 * the run instead (cpu_Done). 0, or -1 when the flash has no free word. */
int fault_hang(avr_t *avr);

/* A reset now: CAUSE "external" (EXTRF), "power" (PORF; SRAM filled with
 * noise, then painted) or "brownout" (BORF). 0, or -1 for another CAUSE. */
int fault_reset(avr_t *avr, board_model_t *bm, const char *cause);

#endif
