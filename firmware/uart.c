#include "firmware/uart.h"

#include <avr/interrupt.h>
#include <avr/wdt.h>
#include <util/atomic.h>

#include "firmware/mcu.h"

_Static_assert((UART_TX_SIZE & (UART_TX_SIZE - 1)) == 0, "tx size is a power of two");

static struct {
	uint8_t tx[UART_TX_SIZE];
	volatile uint8_t tx_head;
	volatile uint8_t tx_tail;
} uart;

ISR(MCU_UART_RX_vect)
{
	uart_line_rx();	/* before UDR is read: the line may look at FE (uart_line.h) */
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
	if (next == uart.tx_tail) {
		/* Full: the UDRE interrupt frees a slot per byte sent. The
		 * watchdog is fed only when one did (progress): a stuck UDRE
		 * interrupt must end in a reset, not spin here fed. */
		while (next == uart.tx_tail) {
		}
		wdt_reset();
	}
	uart.tx[head] = c;
	/* The byte joins the ring and UDRIE goes on in one piece: a UDRE
	 * interrupt in between could send the byte, find the ring empty and
	 * turn UDRIE off, and then UDRIE went on over an empty ring: a stale
	 * byte sent and the tail run past the head (replies garbled now and
	 * then at 460800). The M128-S's UCSR1B is beyond sbi's reach, so its
	 * |= (a load and a store) made that window three instructions wide. */
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		uart.tx_head = next;
		MCU_UCSRB |= _BV(UDRIE);
	}
}
