/*
 * interrupt.h: a repair of simavr 1.6's interrupt queue, to delete with the
 * upgrade to a simavr whose avr_clear_interrupt takes the vector out of its
 * queue (then call that instead):
 *
 *  - a vector withdrawn leaves no entry behind in the queue of pending
 *    interrupts (simavr16_withdraw_interrupt).
 */
#ifndef SIM_SIMAVR16_INTERRUPT_H
#define SIM_SIMAVR16_INTERRUPT_H

#include "sim_avr.h"
#include "sim_interrupts.h"

/* avr_clear_interrupt(AVR, V), and V's entries out of simavr's queue of
 * pending interrupts. For the peripherals whose flags are levels (USART,
 * TWI, SPI): a vector withdrawn when its flag drops. */
void simavr16_withdraw_interrupt(avr_t *avr, avr_int_vector_t *v);

#endif
