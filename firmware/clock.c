#include "firmware/clock.h"

#include <avr/interrupt.h>
#include <stdbool.h>

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

#ifdef BOARD_CLOCK_COMPARE
/* clock_compare_from()'s wrap, while armed. */
static uint8_t compare_armed, compare_from;

void clock_compare_from(uint8_t wrap)
{
	compare_from = wrap;
	compare_armed = 1;
}

void clock_compare_cancel(void)
{
	compare_armed = 0;
}

/* TIFR's flag and TIMSK's enable have the same bit: one AND for both. */
_Static_assert(MCU_CLOCK_OCF == MCU_CLOCK_OCIE, "OCFn and OCIEn share a bit");

/* The compare interrupt is on and flagged, waiting for interrupts. */
static bool clock_compare_pending(void)
{
	return TIFR & TIMSK & MCU_CLOCK_OCF;
}

/* The next overflow is 2048 cycles away: it cannot come again before its
 * end. The compare is turned on at its wrap or, if an overflow was counted
 * by the servo interrupt instead (servo_pins.c), at the next one: "at or
 * after", not "at". Its flag is cleared first, set by the matches while
 * the interrupt was off (it would wake the driver at once for nothing),
 * unless this wrap's match may be among them: the count has reached the
 * compare's, or is two ticks from it (a match between the look and the
 * clearing). Then the interrupt comes at once: late, not a wrap late. */
ISR(MCU_CLOCK_OVF_vect, FRONT_ISR_LETS_RX)
{
	uint8_t now = (uint8_t)++clock_wraps;

	if (compare_armed && (int8_t)(now - compare_from) >= 0) {
		compare_armed = 0;
		uint8_t t = (uint8_t)(MCU_CLOCK_TCNT + 2);

		if (t > 2 && MCU_CLOCK_OCR > t) {  /* 8-bit: no more registers saved */
			TIFR = MCU_CLOCK_OCF;  /* a 1 clears that flag only */
		}
		TIMSK |= MCU_CLOCK_OCIE;
	}
}
#else
static bool clock_compare_pending(void)
{
	return false;
}

/* No driver's compare on the time base (board.h): only the count. */
ISR(MCU_CLOCK_OVF_vect, FRONT_ISR_LETS_RX)
{
	clock_wraps++;
}
#endif

uint8_t clock_lock(void)
{
	uint8_t sreg = SREG;

	for (;;) {
		cli();
		if (!clock_compare_pending()) {
			return sreg;
		}
		SREG = sreg;
	}
}

