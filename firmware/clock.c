#include "firmware/clock.h"

#include <avr/interrupt.h>

#include "board.h"
#include "firmware/front.h"
#include "firmware/mcu.h"

_Static_assert(F_CPU % CLOCK_TICK_CYCLES == 0, "a whole number of ticks per second");

volatile uint16_t clock_wraps;

void clock_init(void)
{
	MCU_CLOCK_TCCR = MCU_CLOCK_CLK8;
	TIMSK |= MCU_CLOCK_TOIE;
}

/* The next overflow is 2048 cycles away: it cannot come again before its end. */
ISR(MCU_CLOCK_OVF_vect, FRONT_ISR_LETS_RX)
{
	clock_wraps++;
}
