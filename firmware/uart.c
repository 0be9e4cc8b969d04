#include "firmware/uart.h"

#include <avr/interrupt.h>
#include <avr/wdt.h>

#include "firmware/front.h"
#include "firmware/mcu.h"

_Static_assert((UART_TX_SIZE & (UART_TX_SIZE - 1)) == 0, "tx size is a power of two");

static struct {
	uint8_t tx[UART_TX_SIZE];
	volatile uint8_t tx_head;
	volatile uint8_t tx_tail;
} uart;

/* Characters front_rx_hold() took from UDR while the receive interrupt
 * could not run, oldest first: the interrupt hands them on before UDR. */
static struct {
	uint8_t c[UART_HOLD];
	uint8_t n;
} held;

ISR(MCU_UART_RX_vect)
{
	uint8_t i = 0;

	for (;;) {
		uint8_t c;

		if (i != held.n) {
			/* Newer characters join the hold before UDR fills. */
			front_rx_hold();
			c = held.c[i++];
		} else if (MCU_UCSRA & _BV(RXC)) {
			uart_line_rx();	/* before UDR is read: the line may look at FE (uart_line.h) */
			c = MCU_UDR;
		} else {
			break;
		}
		uart_received(c);
	}
	held.n = 0;
}

void front_rx_hold(void)
{
	uint8_t n = held.n;

	if ((MCU_UCSRA & _BV(RXC)) && n < UART_HOLD) {
		uart_line_rx();
		held.c[n] = MCU_UDR;
		held.n = (uint8_t)(n + 1);
	}
}

void front_rx_poll(void)
{
	if (held.n || (MCU_UCSRA & _BV(RXC))) {
		/* The receive interrupt called as a function: it keeps every
		 * register it uses; its RETI sets I, and the one instruction
		 * that runs before an interrupt can be taken clears it. */
		__asm__ __volatile__("%~call %x0\n\tcli" : : "i" (MCU_UART_RX_vect) : "memory");
	}
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
	if (next == uart.tx_tail) {
		/* Full: the UDRE interrupt frees a slot per byte sent. The
		 * watchdog is fed only when one did (progress): a stuck UDRE
		 * interrupt must end in a reset, not spin here fed. */
		while (next == uart.tx_tail) {
		}
		wdt_reset();
	}
	uart.tx[head] = c;
	uart.tx_head = next;
	MCU_UCSRB |= _BV(UDRIE);
}
