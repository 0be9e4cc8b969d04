/*
 * Interrupt-driven UART: a receive ring the ISR fills while the main loop
 * executes requests, and a transmit ring drained by the UDRE interrupt.
 */
#ifndef ORFA_UART_H
#define ORFA_UART_H

#include <stdint.h>

/* Receive ring: 8-bit indices wrap for free. It holds 253 characters and
 * keeps two slots for a lost-run record; with the line the parser holds
 * while a request executes, a host with fewer than 256 characters of
 * requests unanswered (SPEC) never overflows it. */
#define UART_RX_SIZE 256
/* Transmit ring: a whole reply line (127 + CR LF) fits, so the main loop
 * rarely waits for the wire. Power of two. */
#define UART_TX_SIZE 128

/* Marks characters lost to a full receive ring: in place of the lost run the
 * ring holds this value and then one byte telling what was lost:
 * UART_LOST_LINES bits = how many line ends of lines with something in them
 * were lost, UART_LOST_TAIL = characters of the line that goes on after the
 * record were lost too. The ISR maps received bytes >= 0x80 to 0x7F, so no
 * byte from the line can look like the marker. */
#define UART_RX_LOST    0x80
#define UART_LOST_LINES 0x7F
#define UART_LOST_TAIL  0x80

/* uart_init() (set the rate, enable the USART) is the line's: see
 * firmware/uart_line.h. */
#include "firmware/uart_line.h"

/* The next received byte, or -1 if none is waiting. */
int16_t uart_getc(void);

/* Nothing received waits to be taken (uart_getc would give -1). */
uint8_t uart_rx_empty(void);

/* Queue one byte for sending; waits only while the transmit ring is full. */
void uart_putc(uint8_t c);

#endif
