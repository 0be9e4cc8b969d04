/*
 * irq_latency.c: how many instructions the CPU runs after SEI, and after
 * RETI, before it takes a pending interrupt, for the simulator's
 * interrupt-latency test (tests/sim/test_irq_latency.py), not ORFA
 * firmware. The ATmega32 datasheet ("Reset and Interrupt Handling"): one
 * after each.
 *
 * With interrupts off, Timer0 raises both its compare and its overflow
 * flag; then, from r16 = 0, SEI and a run of INC r16. The compare
 * interrupt (the higher priority) puts r16 in PORTA's low nibble and
 * returns; the overflow interrupt, taken next, puts r16 in the high
 * nibble. On silicon PORTA ends 0x21: one INC after SEI, one after RETI.
 */
#include <avr/io.h>
#include <avr/interrupt.h>

ISR(TIMER0_COMP_vect, ISR_NAKED)
{
	__asm__ __volatile__("out %0, r16\n\treti" : : "I" (_SFR_IO_ADDR(PORTA)));
}

ISR(TIMER0_OVF_vect, ISR_NAKED)
{
	__asm__ __volatile__("swap r16\n\tin r17, %0\n\tor r17, r16\n\tout %0, r17\n\tswap r16\n\treti"
			     : : "I" (_SFR_IO_ADDR(PORTA)));
}

int main(void)
{
	DDRA = 0xFF;
	OCR0 = 16;
	TCCR0 = _BV(CS00);
	TIMSK = _BV(OCIE0) | _BV(TOIE0);
	while ((TIFR & (_BV(OCF0) | _BV(TOV0))) != (_BV(OCF0) | _BV(TOV0))) {
	}
	TCCR0 = 0;
	__asm__ __volatile__("ldi r16, 0\n\tsei\n\t"
			     "inc r16\n\tinc r16\n\tinc r16\n\tinc r16\n\t"
			     "inc r16\n\tinc r16\n\tinc r16\n\tinc r16\n\tcli"
			     : : : "r16", "r17", "memory");
	for (;;) {
	}
}
