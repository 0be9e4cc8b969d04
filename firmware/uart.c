#include "firmware/uart.h"

#include <avr/interrupt.h>
#include <avr/wdt.h>
#include <util/atomic.h>

#include "firmware/front.h"
#include "firmware/mcu.h"

_Static_assert((UART_TX_SIZE & (UART_TX_SIZE - 1)) == 0, "tx size is a power of two");

static struct {
	uint8_t tx[UART_TX_SIZE];
	volatile uint8_t tx_head;
	volatile uint8_t tx_tail;
} uart;

#ifdef BOARD_RX_BURST
/* A board whose interrupts hold received characters (uart.h). */
_Static_assert((UART_HOLD & (UART_HOLD - 1)) == 0, "hold size is a power of two");

/* Characters front_rx_hold() took from UDR while the receive interrupt
 * could not run, oldest at tail: the interrupt hands them on before UDR. */
static struct {
	uint8_t c[UART_HOLD];
	uint8_t head;
	uint8_t tail;
	uint8_t budget;  /* for a call from front_rx_poll(); 0: BOARD_RX_BURST */
} held;

/* UDR's character, if one waits, into the hold, if it has room. */
static inline __attribute__((always_inline)) void uart_hold(void)
{
	uint8_t head = held.head;

	if ((MCU_UCSRA & _BV(RXC)) && (uint8_t)(head - held.tail) < UART_HOLD) {
		uart_line_rx();	/* before UDR is read: the line may look at FE (uart_line.h) */
		held.c[head & (UART_HOLD - 1)] = MCU_UDR;
		held.head = (uint8_t)(head + 1);
	}
}

/* Hands on the held characters, oldest first, then UDR's, BOARD_RX_BURST
 * at most; while it drains the hold, what arrives goes into the hold too,
 * so UDR never fills behind it. A character left in UDR brings the
 * interrupt back; one left in the hold waits for the next interrupt, the
 * servo interrupt's next release or the main loop (uart_rx_flush()). */
ISR(MCU_UART_RX_vect)
{
	uint8_t budget = held.budget ? held.budget : BOARD_RX_BURST;

	held.budget = 0;
	do {
		uint8_t c;
		uint8_t tail = held.tail;

		if (tail != held.head) {
			uart_hold();
			held.tail = (uint8_t)(tail + 1);
			c = held.c[tail & (UART_HOLD - 1)];
		} else if (MCU_UCSRA & _BV(RXC)) {
			uart_line_rx();	/* before UDR is read: the line may look at FE (uart_line.h) */
			c = MCU_UDR;
		} else {
			break;
		}
		uart_received(c);
	} while (--budget);
}

void uart_rx_flush(void)
{
	if (held.head != held.tail) {
		cli();
		front_rx_poll(FRONT_HOLD_ALL);
		sei();
	}
}

void front_rx_hold(void)
{
	uart_hold();
}

void front_rx_poll(uint8_t most)
{
	if (held.head != held.tail || (MCU_UCSRA & _BV(RXC))) {
		held.budget = most;
		/* The receive interrupt called as a function: it keeps every
		 * register it uses; its RETI sets I, and the one instruction
		 * that runs before an interrupt can be taken clears it. */
		__asm__ __volatile__("%~call %x0\n\tcli" : : "i" (MCU_UART_RX_vect) : "memory");
	}
}

#else
/* Takes what UDR holds: a second character waits there when an interrupt
 * of higher priority ran long (the M128-S's servo compare interrupts can
 * come back to back). */
ISR(MCU_UART_RX_vect)
{
	do {
		uart_line_rx();	/* before UDR is read: the line may look at FE (uart_line.h) */
		uart_received(MCU_UDR);
	} while (MCU_UCSRA & _BV(RXC));
}

void uart_rx_flush(void)
{
}

void front_rx_hold(void)
{
}

void front_rx_poll(uint8_t most)
{
	(void)most;
	if (MCU_UCSRA & _BV(RXC)) {
		/* As above: the receive interrupt called as a function. */
		__asm__ __volatile__("%~call %x0\n\tcli" : : "i" (MCU_UART_RX_vect) : "memory");
	}
}
#endif

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
