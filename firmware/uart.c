#include "firmware/uart.h"

#include <avr/interrupt.h>
#include <util/atomic.h>
#include <avr/wdt.h>

#include "firmware/mcu.h"

_Static_assert(UART_RX_SIZE == 256, "rx indices are uint8_t and wrap at 256");
_Static_assert((UART_TX_SIZE & (UART_TX_SIZE - 1)) == 0, "tx size is a power of two");

static struct {
	uint8_t rx[UART_RX_SIZE];
	uint8_t tx[UART_TX_SIZE];
	volatile uint8_t rx_head;  /* written by the ISR */
	volatile uint8_t rx_tail;  /* written by the main loop */
	volatile uint8_t tx_head;
	volatile uint8_t tx_tail;
	volatile uint8_t lost;  /* characters are being lost */
	uint8_t lost_lines;  /* line ends lost in this run */
	uint8_t lost_tail;   /* the line going on has lost characters */
	uint8_t content;     /* the line being received has a non-space */
} uart;

ISR(MCU_UART_RX_vect)
{
	uart_line_rx();	/* before UDR is read: the line may look at FE (uart_line.h) */
	uint8_t c = MCU_UDR;
	uint8_t head = uart.rx_head;
	uint8_t room = (uint8_t)(uart.rx_tail - head - 1);
	uint8_t line_end = (c == '\r' || c == '\n');
	uint8_t had_content = uart.content;

	/* Whether the line in progress has anything but spaces, stored or not:
	 * a lost line end counts only for such a line (an empty line or CR LF's
	 * LF gets no reply, so it must not get an error either). */
	if (line_end) {
		uart.content = 0;
	} else if (c != ' ') {
		uart.content = 1;
	}
	if (c >= UART_RX_LOST) {
		c = 0x7F;
	}
	if (uart.lost) {
		if (room < 3) {
			if (line_end) {
				if (had_content && uart.lost_lines < UART_LOST_LINES) {
					uart.lost_lines++;
				}
				uart.lost_tail = 0;
			} else {
				uart.lost_tail = 1;
			}
			return;
		}
		/* Room again: the record of the lost run, then this byte. */
		uart.rx[head] = UART_RX_LOST;
		head = (uint8_t)(head + 1);
		uart.rx[head] = (uint8_t)(uart.lost_lines | (uart.lost_tail ? UART_LOST_TAIL : 0));
		head = (uint8_t)(head + 1);
		uart.lost = 0;
	} else if (room < 3) {
		/* Full: two slots stay free for the record of what is lost. */
		uart.lost = 1;
		uart.lost_lines = (line_end && had_content) ? 1 : 0;
		uart.lost_tail = !line_end;
		return;
	}
	uart.rx[head] = c;
	uart.rx_head = (uint8_t)(head + 1);
}

/* The record of a lost run that no byte followed yet (the host stopped
 * sending): written once the ring is empty, so the lost requests get their
 * replies without waiting for more input. */
static void uart_close_lost_run(void)
{
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		if (uart.lost && uart.rx_tail == uart.rx_head) {
			uint8_t head = uart.rx_head;
			uart.rx[head] = UART_RX_LOST;
			uart.rx[(uint8_t)(head + 1)] =
				(uint8_t)(uart.lost_lines | (uart.lost_tail ? UART_LOST_TAIL : 0));
			uart.rx_head = (uint8_t)(head + 2);
			uart.lost = 0;
		}
	}
}

int16_t uart_getc(void)
{
	uint8_t tail = uart.rx_tail;
	if (tail == uart.rx_head) {
		if (!uart.lost) {
			return -1;
		}
		uart_close_lost_run();
		tail = uart.rx_tail;
		if (tail == uart.rx_head) {
			return -1;
		}
	}
	uint8_t c = uart.rx[tail];
	uart.rx_tail = (uint8_t)(tail + 1);
	return c;
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

/* For the line's rate keeper (uart_line.h): nothing waits in the ring. */
uint8_t uart_rx_empty(void)
{
	return uart.rx_tail == uart.rx_head && !uart.lost;
}
