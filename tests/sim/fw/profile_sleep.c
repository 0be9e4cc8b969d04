/*
 * A board asleep for the simulator's `profile` request
 * (tests/sim/test_profile.py): SLEEP (idle), NOP, RJMP back, the SLEEP at
 * the global label profile_sleep. Timer0's overflow (/1024, an empty
 * handler) wakes it every 262144 cycles; Timer1 runs free without an
 * interrupt, so the simulator's timers fire several times in each sleep.
 */
#include <avr/interrupt.h>
#include <avr/io.h>

EMPTY_INTERRUPT(TIMER0_OVF_vect);

int main(void)
{
	TCCR1B = _BV(CS10);
	TCCR0 = _BV(CS02) | _BV(CS00);
	TIMSK = _BV(TOIE0);
	MCUCR |= _BV(SE);
	sei();
	__asm__ __volatile__(
		".global profile_sleep\n"
		"profile_sleep:\n"
		"	sleep\n"
		"	nop\n"
		"	rjmp profile_sleep\n");
	return 0;
}
