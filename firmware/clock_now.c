#include "firmware/clock.h"

/* Without turning interrupts off: on the M32-D a main loop that does so now
 * and then delays the servo edge interrupt past its exact cycle (measured:
 * 200 streamed servo writes fell behind the wire). Two equal readings in a
 * row are not torn: the wraps are 2048 cycles apart. Pure C, so the host
 * tests link it too. Not inlined: one copy is smaller than three. */
__attribute__((noinline)) uint16_t clock_now(void)
{
	uint16_t t;
	do {
		t = clock_wraps;
	} while (t != clock_wraps);
	return t;
}
