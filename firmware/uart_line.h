/*
 * The serial line's rate: who sets UBRR and when the USART listens.
 * Two implementations, one linked per build (Makefile, BAUD=):
 *   firmware/uart_rate.c  a fixed rate (BAUD=115200, ...), set at once;
 *   firmware/autobaud.c   BAUD=auto: the rate found from the PC's 0x0D
 *                         preamble (docs/protocol.md, "Autobaud").
 * In a fixed-rate build the hooks below are empty and vanish (-flto).
 */
#ifndef ORFA_UART_LINE_H
#define ORFA_UART_LINE_H

#include <stdint.h>

/* After reset: the fixed rate's USART on, or autobaud armed. */
void uart_init(void);

/* From the main loop when nothing received waits: nonzero when the line
 * has no rate or a new one (autobaud detecting; may take up to ~60 ms per
 * call); the front end then drops what it holds of the line. */
uint8_t uart_line_poll(void);

/* From the receive interrupt, before UDR is read (UCSRA still holds the
 * frame's FE). */
void uart_line_rx(void);

/* A request was accepted: the rate is proven. */
void uart_line_confirm(void);

#endif
