/*
 * avr_step.h: a board's MCU run instruction by instruction up to a cycle,
 * as simavr 1.6's avr_run() (avr_callback_run_raw) runs it, without its
 * per-instruction costs: the cycle timers are processed only when the
 * first of them is due (simavr walks them after every instruction and
 * finds none due almost always). Same instructions, same timer calls at
 * the same cycles, same interrupt servicing: only faster.
 */
#ifndef SIM_AVR_STEP_H
#define SIM_AVR_STEP_H

#include <stdint.h>

#include "sim_avr.h"

/* What avr_callback_run_raw() does after an instruction: the timers due,
 * the PC to NEW_PC, sleep, the interrupts. */
void avr_step_after(avr_t *avr, avr_flashaddr_t new_pc);

/* Run AVR until its cycle reaches END (the instruction that crosses it
 * completes). Returns the MCU's state: cpu_Done or cpu_Crashed end the
 * run at once. */
int avr_step_until(avr_t *avr, uint64_t end);

#endif
