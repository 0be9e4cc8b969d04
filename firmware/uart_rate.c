/* A fixed line rate (BAUD=<rate>): see uart_line.h. */
#include "firmware/uart_line.h"

#include <avr/io.h>

#include "firmware/mcu.h"

#ifndef ORFA_BAUD
#define ORFA_BAUD 115200
#endif

#define UART_UBRR ((F_CPU + 8UL * ORFA_BAUD) / (16UL * ORFA_BAUD) - 1)

_Static_assert(UART_UBRR < 4096, "baud rate too low for this clock");

/* 8N1 is the reset value of the frame format on both MCUs. */
static void uart_start(uint16_t ubrr)
{
	MCU_UBRRH = (uint8_t)(ubrr >> 8);
	MCU_UBRRL = (uint8_t)ubrr;
	MCU_UCSRB = _BV(RXEN) | _BV(TXEN) | _BV(RXCIE);
}

void uart_init(void)
{
	uart_start(UART_UBRR);
}

uint8_t uart_line_poll(void)
{
	return 0;
}

void uart_line_rx(void)
{
}

void uart_line_confirm(void)
{
}
