/*
 * interrupt.h: a repair of simavr 1.6's interrupt queue, to delete with the
 * upgrade to a simavr whose avr_clear_interrupt takes the vector out of its
 * queue (then call that instead):
 *
 *  - a vector withdrawn leaves no entry behind in the queue of pending
 *    interrupts (simavr16_withdraw_interrupt);
 *  - one instruction, not two, runs after SEI or RETI before a pending
 *    interrupt is taken (simavr16_interrupt_latency).
 */
#ifndef SIM_SIMAVR16_INTERRUPT_H
#define SIM_SIMAVR16_INTERRUPT_H

#include "sim_avr.h"
#include "sim_interrupts.h"

/* avr_clear_interrupt(AVR, V), and V's entries out of simavr's queue of
 * pending interrupts. For the peripherals whose flags are levels (USART,
 * TWI, SPI): a vector withdrawn when its flag drops. */
void simavr16_withdraw_interrupt(avr_t *avr, avr_int_vector_t *v);

/* The AVR "always executes one more instruction" after RETI, and the one
 * after SEI, before it serves a pending interrupt (the ATmega32/128
 * datasheets, "Reset and Interrupt Handling"). simavr 1.6 marks an I bit
 * set (avr_sreg_set) with interrupt_state -2 and counts it up once after
 * that instruction and once after the next, so the next two run first: a
 * main loop whose second instruction after a receive interrupt's RETI is a
 * CLI kept a pending servo compare out for a whole interrupts-off section
 * more than on silicon (a pulse ~90 cycles long). Called after every
 * instruction, before avr_service_interrupts(): the mark counts as the
 * first step already taken. */
static inline void simavr16_interrupt_latency(avr_t *avr)
{
	if (avr->interrupt_state == -2) {
		avr->interrupt_state = -1;
	}
}

#endif
