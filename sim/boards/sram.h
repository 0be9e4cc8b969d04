/*
 * sram.h: a board's SRAM as the stack measurement sees it: painted with
 * SRAM_PAINT at power-on, the paint the stack has overwritten its peak.
 */
#ifndef SIM_SRAM_H
#define SIM_SRAM_H

#include <stdint.h>

#include "sim_avr.h"

/* Byte the simulator paints free SRAM with before the firmware runs. */
#define SRAM_PAINT 0xA5

/* Fill SRAM with SRAM_PAINT (power-on: start-up and `reset power`). */
void sram_paint(avr_t *avr);

/* Peak stack use since the last power-on, in bytes: from the first byte
 * above FROM (the end of the firmware's static data, __heap_start; 0 =
 * guess) that the stack has written. *deepest = that address. -1 if FROM
 * is not SRAM. */
int sram_stack_peak(avr_t *avr, uint32_t from, uint32_t *deepest);

#endif
