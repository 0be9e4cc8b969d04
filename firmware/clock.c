#include "firmware/clock.h"

#include <avr/interrupt.h>

#include "firmware/mcu.h"

_Static_assert(F_CPU % CLOCK_TICK_CYCLES == 0, "a whole number of ticks per second");

volatile uint16_t clock_wraps;

void clock_init(void)
{
	MCU_CLOCK_TCCR = MCU_CLOCK_CLK8;
	TIMSK |= MCU_CLOCK_TOIE;
}

ISR(MCU_CLOCK_OVF_vect)
{
	clock_wraps++;
}
