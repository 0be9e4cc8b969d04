/* The front end linked into this build: the serial gateway (MODE=gate) or
 * the I2C slave (MODE=slave). main() only knows this interface. */
#ifndef ORFA_FRONT_H
#define ORFA_FRONT_H

#include <stdint.h>

#include "board.h"  /* BOARD_RX_BURST: a hold */

void front_init(void);
/* One step of the front end's work; when it has none, it calls sys_poll()
 * (the link-loss failsafe): the busy path pays nothing for it. */
void front_poll(void);

/*
 * For an interrupt that keeps interrupts off longer than the serial line's
 * receiver holds characters (two in UDR: 320 cycles at 460800 baud) and
 * cannot let the receive interrupt run at every point (drivers/servo_pins.c
 * between its wake-up and an edge). Both are empty in the I2C slave.
 *
 * front_rx_hold(): takes a waiting character from UDR into a small hold
 * (a dozen cycles), from which the receive interrupt hands it on first.
 * front_rx_poll(most): lets the receive interrupt run now, if anything is
 * held or waits in UDR, to hand on `most` characters at most (about 70
 * cycles each; FRONT_HOLD_ALL: everything); a pending interrupt of higher
 * priority may run instead: the caller allows for the longest. Called with
 * interrupts off, returns with them off, and (a board with a hold) with
 * the number of characters still held (not 0: `most` ran out before the
 * hold did; a count, not a bool: no compare, 6 bytes).
 */
#define FRONT_HOLD_ALL 0xFF

/* The ISR() attribute of an interrupt with no deadline of its own (the
 * ADC's, the clock tick's) that cannot come again before it ends: on a
 * board whose receive interrupt they outrank (BOARD_RX_OUTRANKED) it runs
 * with interrupts on (ISR_NOBLOCK), so the receive interrupt waits for
 * none of it. Elsewhere it blocks: the M32-D's servo interrupt has a
 * budget for the others that run before it. */
#ifdef BOARD_RX_OUTRANKED
#define FRONT_ISR_LETS_RX ISR_NOBLOCK
#define FRONT_ISR_LETS_RX_ASM "sei\n\t"
#else
#define FRONT_ISR_LETS_RX ISR_BLOCK
#define FRONT_ISR_LETS_RX_ASM ""
#endif
/* FRONT_ISR_LETS_RX_ASM: the same for an ISR_NAKED handler, its first
 * instruction(s). */

void front_rx_hold(void);
#ifdef BOARD_RX_BURST
typedef uint8_t front_rx_left_t;
#else
/* No hold: nothing to tell, and no instruction to tell it (the M128-S's
 * compare interrupts call it at every edge). */
typedef void front_rx_left_t;
#endif
front_rx_left_t front_rx_poll(uint8_t most);
/* Before such an interrupt returns, after its last front_rx_hold(): what
 * the hold keeps is told to the receive interrupt's fast path (a few
 * cycles; nothing in the I2C slave). */
void front_rx_held(void);

#endif
