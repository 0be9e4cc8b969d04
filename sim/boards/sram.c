/*
 * sram.c: SRAM painting and the stack peak (sram.h).
 */
#include "boards/sram.h"
/* Stack painting: SRAM keeps its contents over a reset, as on silicon, so
 * the simulator fills it with SRAM_PAINT at power-on (start-up and `reset
 * power`), before the firmware starts; the startup code then initialises
 * .data and .bss, and the stack overwrites the paint as deep as it ever
 * goes. Other resets (watchdog, external, brown-out) keep SRAM: .noinit
 * data survive them, and the stack peak counts from power-on. */
void sram_paint(avr_t *avr)
{
	for (uint32_t a = avr->ioend + 1u; a <= avr->ramend; a++) {
		avr->data[a] = SRAM_PAINT;
	}
}

int sram_stack_peak(avr_t *avr, uint32_t from, uint32_t *deepest)
{
	uint32_t a;

	if (from == 0) {
		/* Not told where the static data end: the stack lies above the
		 * highest run of 16 untouched bytes. */
		uint32_t run = 0;
		for (a = avr->ramend; a > avr->ioend; a--) {
			run = (avr->data[a] == SRAM_PAINT) ? run + 1 : 0;
			if (run == 16) {
				break;
			}
		}
		from = a;
	}
	if (from <= avr->ioend || from > avr->ramend) {
		return -1;
	}
	for (a = from; a <= avr->ramend && avr->data[a] == SRAM_PAINT; a++) {
	}
	*deepest = a;
	return (int)(avr->ramend + 1u - a);
}
