/*
 * The quiet rule: how a slave tells a write frame that its master abandoned
 * from one that ended (docs/protocol.md, "Abandoned frames").
 *
 * The bus has no abort signal, and any START or STOP ends a slave's frame as
 * if it were complete, so a master that gives up says it by silence:
 *  - a slave drops an open frame (a write in it is not applied) that has had
 *    no bus event for longer than TWI_QUIET_DROP_MS, and also when the event
 *    that ends it comes later than that;
 *  - a gateway that gave up on a transaction in the middle (a step timed
 *    out, arbitration lost, a bus error) or has just reset puts nothing on
 *    the bus (no START, no `X` clocks or STOP) until TWI_QUIET_FENCE_MS have
 *    passed: by then every slave has dropped the frame, whichever address
 *    the next request goes to.
 * A healthy master never leaves a frame that quiet: at the slowest clock the
 * gateway sets (about 1 kHz) a byte and its ACK take 9.2 ms, and the
 * gateway's work between two bytes is a few hundred cycles.
 */
#ifndef ORFA_TWI_QUIET_H
#define ORFA_TWI_QUIET_H

#include "firmware/clock.h"

/* SMBus gives a device 25-35 ms to give up on a stalled transfer. */
#define TWI_QUIET_DROP_MS 30
/* On top of the drop: the slave's tick (0.28 ms) rounding on both sides and
 * the slave's main loop coming round to look. */
#define TWI_QUIET_FENCE_MS 36

#define TWI_QUIET_DROP_TICKS CLOCK_TICKS_MS(TWI_QUIET_DROP_MS)
#define TWI_QUIET_FENCE_TICKS CLOCK_TICKS_MS(TWI_QUIET_FENCE_MS)

_Static_assert(TWI_QUIET_FENCE_TICKS >= TWI_QUIET_DROP_TICKS + 8,
	       "the gateway stays quiet longer than a slave takes to drop a frame");
_Static_assert(TWI_QUIET_FENCE_TICKS < 250, "the low byte of the clock measures both");
/* The slowest bus clock (TWBR 58, TWPS 3: 982 Hz): 9 SCL periods a byte. */
_Static_assert(9UL * (16 + 2 * 58 * 64) < TWI_QUIET_DROP_TICKS * CLOCK_TICK_CYCLES / 2,
	       "a healthy frame's slowest byte is far shorter than the drop time");

#endif
