#include "firmware/uart.h"

#include <avr/interrupt.h>
#include <avr/wdt.h>

#include "firmware/mcu.h"

#ifndef ORFA_BAUD
#define ORFA_BAUD 115200
#endif

#define UART_UBRR ((F_CPU + 8UL * ORFA_BAUD) / (16UL * ORFA_BAUD) - 1)

_Static_assert((UART_TX_SIZE & (UART_TX_SIZE - 1)) == 0, "tx size is a power of two");
_Static_assert(UART_UBRR < 4096, "baud rate too low for this clock");

static struct {
	uint8_t tx[UART_TX_SIZE];
	volatile uint8_t tx_head;
	volatile uint8_t tx_tail;
} uart;

void uart_init(void)
{
	MCU_UBRRH = (uint8_t)(UART_UBRR >> 8);
	MCU_UBRRL = (uint8_t)UART_UBRR;
	/* 8N1 is the reset value of the frame format on both MCUs. */
	MCU_UCSRB = _BV(RXEN) | _BV(TXEN) | _BV(RXCIE);
}

ISR(MCU_UART_RX_vect)
{
	uart_received(MCU_UDR);
}

ISR(MCU_UART_UDRE_vect)
{
	uint8_t tail = uart.tx_tail;
	MCU_UDR = uart.tx[tail];
	tail = (uint8_t)((tail + 1) & (UART_TX_SIZE - 1));
	uart.tx_tail = tail;
	if (tail == uart.tx_head) {
		MCU_UCSRB &= (uint8_t)~_BV(UDRIE);
	}
}

void uart_putc(uint8_t c)
{
	/* Fast path for the first byte of a reply: straight into UDR. */
	if (uart.tx_head == uart.tx_tail && (MCU_UCSRA & _BV(UDRE))) {
		MCU_UDR = c;
		return;
	}
	uint8_t head = uart.tx_head;
	uint8_t next = (uint8_t)((head + 1) & (UART_TX_SIZE - 1));
	while (next == uart.tx_tail) {
		wdt_reset();
	}
	uart.tx[head] = c;
	uart.tx_head = next;
	MCU_UCSRB |= _BV(UDRIE);
}
