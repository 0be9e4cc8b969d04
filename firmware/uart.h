/*
 * Interrupt-driven UART: received bytes handed to the front end from the
 * receive interrupt (serialgate/sg_rx.c rings them), and a transmit ring
 * drained by the UDRE interrupt.
 */
#ifndef ORFA_UART_H
#define ORFA_UART_H

#include <stdint.h>

#include "board.h"

/* Transmit ring: half a longest reply (127 + CR LF). A long reply holds the
 * main loop for the other half's wire time, while the receive ring takes
 * what arrives; the reply's first byte goes out at once, so latency is not
 * affected, and 64 bytes of the ATmega32's 2 KB are kept for the stack
 * (make bench: the same requests/s and servo streaming as with 128). Power
 * of two. */
#define UART_TX_SIZE 64

/*
 * The receive hold (front_rx_hold(), firmware/front.h), on a board whose
 * interrupts keep characters from the receive interrupt (BOARD_RX_BURST in
 * its board file: the M32-D's servo interrupt, which waits for cycle-exact
 * edges with interrupts off): UART_HOLD characters, more than reach UDR
 * while that interrupt runs at 460800 baud (about 800 cycles for an edge,
 * 400 more for each close one); a receive interrupt hands on
 * BOARD_RX_BURST of them at most. Elsewhere the receive interrupt takes
 * UDR's character alone and there is no hold.
 */
#define UART_HOLD 16

/* CPU cycles a character lasts on the line at the fastest rate the build
 * may run (ORFA_BAUD_TOP: BAUD, or autobaud's fastest): 640 at 115200,
 * 160 at 460800. */
#define UART_CHAR_CYCLES ((int16_t)(F_CPU * 10 / ORFA_BAUD_TOP))

/* uart_init() (set the rate, enable the USART) is the line's: see
 * firmware/uart_line.h. */
#include "firmware/uart_line.h"

/* Each received byte, from the receive interrupt: the front end's. */
void uart_received(uint8_t c);

/* From the main loop when the front end has nothing to do: hands on what
 * the receive hold still keeps. */
void uart_rx_flush(void);

/* Queue one byte for sending; waits only while the transmit ring is full. */
void uart_putc(uint8_t c);

/* Two bytes, A first (a reply's hex digits, its line end): one call. */
void uart_put2(uint8_t a, uint8_t b);

#endif
