/*
 * Interrupt-driven UART: received bytes handed to the front end from the
 * receive interrupt (serialgate/sg_rx.c rings them), and a transmit ring
 * drained by the UDRE interrupt.
 */
#ifndef ORFA_UART_H
#define ORFA_UART_H

#include <stdint.h>

/* Transmit ring: a whole reply line (127 + CR LF) fits, so the main loop
 * rarely waits for the wire. Power of two. */
#define UART_TX_SIZE 128

void uart_init(void);

/* Each received byte, from the receive interrupt: the front end's. */
void uart_received(uint8_t c);

/* Queue one byte for sending; waits only while the transmit ring is full. */
void uart_putc(uint8_t c);

#endif
