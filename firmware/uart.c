#include "firmware/uart.h"

#include <stdbool.h>

#include <avr/interrupt.h>
#include <avr/wdt.h>
#include <util/atomic.h>

#include "firmware/clock.h"
#include "firmware/front.h"
#include "firmware/mcu.h"
#include "serialgate/sg_rx.h"

_Static_assert((UART_TX_SIZE & (UART_TX_SIZE - 1)) == 0, "tx size is a power of two");

/* Where the receive and transmit interrupts' assembly keeps SREG: EEDR,
 * the EEPROM's data register, as a plain register (nothing in the firmware
 * touches the EEPROM: tests/host/test_architecture.py keeps EEDR to this
 * file). An out and an in, a cycle each, where a push and a pop took two
 * each: 2 cycles less a character each way, ~60 a request of 460800's
 * back-to-back burst. Only these two handlers use it, and neither enables
 * interrupts, so neither runs inside the other. (SREG in r2, kept from the
 * compiler with -ffixed-r2, saves 4, but the servo planner then has a
 * register less: the M128-S's 16-triple write ~3 % slower.) */
#define ISR_KEEP _SFR_IO_ADDR(EEDR)

static struct {
	uint8_t tx[UART_TX_SIZE];
	volatile uint8_t tx_head;
	volatile uint8_t tx_tail;
} uart;

/* The receive interrupt's whole work, an interrupt handler of its own
 * (it keeps every register it uses, ends in RETI): the vector's fast path
 * (below) jumps to it for anything but a plain character, and
 * front_rx_poll() calls it. Its name begins with __vector, as the
 * compiler wants of a handler. */
void uart_rx_all(void) __asm__("__vector_uart_rx_all") __attribute__((signal, used, externally_visible));
#define RX_ALL_HANDLER void uart_rx_all(void)

/* UDR's character, the line told first: it may look at FE, which reading
 * UDR clears (uart_line.h). */
static inline __attribute__((always_inline)) uint8_t udr_take(void)
{
	uart_line_rx();
	return MCU_UDR;
}

/* The receive interrupt called as a function: it keeps every register it
 * uses; its RETI sets I, and the one instruction that runs before an
 * interrupt can be taken clears it. Interrupts off. */
static inline __attribute__((always_inline)) void rx_all_call(void)
{
	__asm__ __volatile__("%~call %x0\n\tcli" : : "i" (uart_rx_all) : "memory");
}

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

/* UDR's characters, both if two wait, into the hold, as it has room. One
 * a call left the second in UDR: after a release that ran out of its
 * budget the USART stayed two behind, and the servo interrupt's last
 * stretch (~260 cycles without a call) then lost the third at 460800. */
static inline __attribute__((always_inline)) void uart_hold(void)
{
	uint8_t head = held.head;

	while ((MCU_UCSRA & _BV(RXC)) && (uint8_t)(head - held.tail) < UART_HOLD) {
		held.c[head & (UART_HOLD - 1)] = udr_take();
		held.head = ++head;
	}
}

/* The hold's state in the ring's line byte (SG_RX_LINE_HELD), where the
 * receive interrupt's fast path tests it with the line's: one compare for
 * both. Told where the hold may have changed before interrupts are on
 * again: at the end of uart_rx_all() and as the servo interrupt returns
 * (front_rx_held()); not in uart_hold(), whose cycles in the servo
 * interrupt's wait for an edge are counted (a mark there made an edge
 * late at 460800). */
static inline __attribute__((always_inline)) void held_tell(void)
{
#ifdef ORFA_BAUD  /* autobaud's receive interrupt has no fast path to tell */
	if (held.tail == held.head) {
		sg_rx.line &= (uint8_t)~SG_RX_LINE_HELD;
	} else {
		sg_rx.line |= SG_RX_LINE_HELD;
	}
#endif
}

/* Hands on the held characters, oldest first, then UDR's, BOARD_RX_BURST
 * at most; while it drains the hold, what arrives goes into the hold too,
 * so UDR never fills behind it. A character left in UDR brings the
 * interrupt back; one left in the hold waits for the next interrupt, the
 * servo interrupt's next release or the main loop (uart_rx_flush()). */
RX_ALL_HANDLER
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
			c = udr_take();
		} else {
			break;
		}
		uart_received(c);
	} while (--budget);
	held_tell();  /* sg_rx_put() may have rewritten the line byte */
}

/* BOARD_RX_BURST at a time, as the receive interrupt: interrupts are off
 * while it runs, and the servo interrupt's lead allows for that many (all
 * sixteen the hold can keep, ~1400 cycles, made an edge 8-11 cycles late
 * at 460800). After the servo's compare if it waits (clock_lock()): a
 * receive interrupt that returned to a plain CLI here ran it as its one
 * instruction, and the compare waited for both (an edge ~90 cycles late
 * at 115200). The main loop comes back for the rest. */
void uart_rx_flush(void)
{
	if (held.head != held.tail) {
		uint8_t sreg = clock_lock();
		front_rx_poll(BOARD_RX_BURST);
		SREG = sreg;
	}
}

void front_rx_hold(void)
{
	uart_hold();
}

void front_rx_held(void)
{
	held_tell();
}

front_rx_left_t front_rx_poll(uint8_t most)
{
	if (held.head != held.tail || (MCU_UCSRA & _BV(RXC))) {
		held.budget = most;
		rx_all_call();
	}
	return (uint8_t)(held.head - held.tail);
}

#else
/* Takes what UDR holds: a second character waits there when an interrupt
 * of higher priority ran long (the M128-S's servo compare interrupts can
 * come back to back). */
RX_ALL_HANDLER
{
	do {
		uart_received(udr_take());
	} while (MCU_UCSRA & _BV(RXC));
}

void uart_rx_flush(void)
{
}

void front_rx_hold(void)
{
}

void front_rx_held(void)
{
}

front_rx_left_t front_rx_poll(uint8_t most)
{
	(void)most;
	if (MCU_UCSRA & _BV(RXC)) {
		rx_all_call();
	}
}
#endif

/* The receive interrupt at 460800 has 160 cycles a character, the
 * parser's share and the reply's included; the whole handler's register
 * saves alone cost ~60. Its fast path takes the common character with
 * three registers (the vector runs only while UDR holds a character: no
 * other code calls it): one inside a line, a request's first letter, a
 * line's CR or LF (sg_rx.h's rule), the ring not losing and with room, the
 * M32-D's hold empty (SG_RX_LINE_HELD, in the same byte as the line's
 * state: one test for both). Anything else goes to
 * uart_rx_all(), which on the M32-D finds a character already read from
 * UDR in the hold, first in line; on the M128-S such a character goes to
 * uart_received() with the call-clobbered registers saved. A rate found
 * by autobaud needs uart_line_rx() on every character: uart_rx_all(). */
/* `in` where UDR is in I/O space (the M32-D's: a cycle and a word less
 * than `lds`), else `lds`: an assembler condition on the memory address. */
#define RX_IO_LOAD(reg, sfr) \
	".if " sfr " < 0x60\n\tin " reg ", " sfr " - 0x20\n\t.else\n\tlds " reg ", " sfr "\n\t.endif\n\t"
/* The fast path's registers back, SREG (from ISR_KEEP) before the last, as they were. */
#define RX_FAST_RESTORE \
	"pop r31\n\tpop r30\n\tin r24, %[keep]\n\tout __SREG__, r24\n\tpop r24\n\t"

ISR(MCU_UART_RX_vect, ISR_NAKED)
{
#ifdef ORFA_BAUD
	__asm__ __volatile__(
		"push r24\n\t"
		"in r24, __SREG__\n\t"
		"out %[keep], r24\n\t"
		"push r30\n\t"
		"push r31\n\t"
		"lds r24, %[line]\n\t"
		"cpi r24, %[plain]\n\t"
		"brne 8f\n\t"
		"lds r30, %[head]\n\t"
		"lds r31, %[tail]\n\t"
		"sub r31, r30\n\t"
		"subi r31, 1\n\t"
		"cpi r31, %[record] + 1\n\t"
		"brlo 10f\n\t"
		RX_IO_LOAD("r24", "%[udr]")
		"tst r24\n\t"
		"brmi 3f\n\t"
		"cpi r24, 0x20\n\t"
		"brsh 6f\n\t"
		"cpi r24, '\\n'\n\t"
		"breq 5f\n\t"
		"cpi r24, '\\r'\n\t"
		"brne 3f\n"
		"5:\n\t"
		"ldi r31, 0\n\t"
		"sts %[line], r31\n"	/* the line's end: a new line next */
		"6:\n\t"
		/* buf[head] = c; head + 1 (r30 = head + lo8(buf), less lo8(buf) - 1) */
		"ldi r31, 0\n\t"
		"subi r30, lo8(-(%[buf]))\n\t"
		"sbci r31, hi8(-(%[buf]))\n\t"
		"st Z, r24\n\t"
		"subi r30, lo8(%[buf] - 1)\n\t"
		"sts %[head], r30\n"
		"1:\n\t"
		RX_FAST_RESTORE
		"reti\n"
		"10:\n\t"
		"rjmp 2f\n"
		"8:\n\t"
		/* a new line (line 0, nothing being lost): its first
		 * character, a request's letter, makes it plain (sg_rx.h's
		 * rule); a space, a '#', a mark's range: uart_rx_all() */
		"tst r24\n\t"
		"brne 2f\n\t"
		"lds r24, %[losing]\n\t"
		"tst r24\n\t"
		"brne 2f\n\t"
		"lds r30, %[head]\n\t"
		"lds r31, %[tail]\n\t"
		"sub r31, r30\n\t"
		"subi r31, 1\n\t"
		"cpi r31, %[record] + 1\n\t"
		"brlo 2f\n\t"
		RX_IO_LOAD("r24", "%[udr]")
		"cpi r24, 0x21\n\t"
		"brlo 9f\n\t"
		"tst r24\n\t"
		"brmi 3f\n\t"
		"cpi r24, '#'\n\t"
		"breq 3f\n\t"
		"ldi r31, %[plain]\n\t"
		"sts %[line], r31\n\t"
		"rjmp 6b\n"
		"9:\n\t"
		/* an empty line's CR or LF: as is, the line stays 0 */
		"cpi r24, '\\n'\n\t"
		"breq 6b\n\t"
		"cpi r24, '\\r'\n\t"
		"breq 6b\n\t"
		"rjmp 3f\n"
#ifdef BOARD_RX_BURST
		"3:\n\t"
		/* into the empty hold: uart_rx_all() takes it first */
		"lds r30, %[hhead]\n\t"
		"andi r30, %[hmask]\n\t"
		"ldi r31, 0\n\t"
		"subi r30, lo8(-(%[hbuf]))\n\t"
		"sbci r31, hi8(-(%[hbuf]))\n\t"
		"st Z, r24\n\t"
		"lds r30, %[hhead]\n\t"
		"subi r30, 0xFF\n\t"
		"sts %[hhead], r30\n"
#endif
		"2:\n\t"
		RX_FAST_RESTORE
		"%~jmp %x[all]\n"
#ifndef BOARD_RX_BURST
		"3:\n\t"
		"push r0\n\t"
		"push r1\n\t"
		"clr r1\n\t"
		"push r18\n\t"
		"push r19\n\t"
		"push r20\n\t"
		"push r21\n\t"
		"push r22\n\t"
		"push r23\n\t"
		"push r25\n\t"
		"push r26\n\t"
		"push r27\n\t"
		"%~call %x[recv]\n\t"
		"pop r27\n\t"
		"pop r26\n\t"
		"pop r25\n\t"
		"pop r23\n\t"
		"pop r22\n\t"
		"pop r21\n\t"
		"pop r20\n\t"
		"pop r19\n\t"
		"pop r18\n\t"
		"pop r1\n\t"
		"pop r0\n\t"
		"rjmp 1b\n"
#endif
		: : [keep] "I" (ISR_KEEP), [udr] "n" (_SFR_MEM_ADDR(MCU_UDR)), [line] "i" (&sg_rx.line),
		[plain] "n" (SG_RX_LINE_PLAIN), [head] "i" (&sg_rx.head), [tail] "i" (&sg_rx.tail),
		[losing] "i" (&sg_rx.losing), [record] "n" (SG_RX_RECORD), [buf] "i" (sg_rx.buf),
		[all] "i" (uart_rx_all),
#ifdef BOARD_RX_BURST
		[hhead] "i" (&held.head), [hbuf] "i" (held.c),
		[hmask] "n" (UART_HOLD - 1)
#else
		[recv] "i" (uart_received)
#endif
	);
#else
	__asm__ __volatile__("%~jmp %x0" : : "i" (uart_rx_all));
#endif
}

/* The transmit side's rule, which uart_putc() and this interrupt keep:
 * UDRIE is on whenever the ring holds a byte. Only this interrupt turns it
 * off, in the same run that sends the ring's last byte; only tx_publish()
 * (uart_putc, uart_put2) turns it on, and only after its bytes are in the
 * ring (head stored) and while UDRIE is off, so while no UDRE interrupt can
 * run: then the tail it compares with stands still. So the main loop that
 * finds UDRIE off knows the ring empty and UDR its own (tx_direct()), and
 * the interrupt never runs over an empty ring (which sent a stale byte and
 * ran the tail past the head: replies garbled now and then at 460800).
 * Nothing else changes UCSRB but uart_init() and autobaud (with interrupts
 * off, keeping UDRIE).
 *
 * The interrupt: the ring's next byte into UDR, UDRIE off when the ring is
 * empty. In assembly with two registers saved and SREG kept in ISR_KEEP:
 * the compiler's handler also saved r0, r1, r24 and r25 and cleared r1. UCSRB's
 * read-modify-write (the M128-S's UCSR1B is beyond cbi's reach) is safe:
 * the main loop changes it only while UDRIE is off or with interrupts off. */
/* `out`/`cbi` where the register is in I/O space (the M32-D's, the M128-S's
 * USART0), else `sts`/`lds`: assembler conditions on the memory address. */
#define TX_IO_STORE(sfr, reg) \
	".if " sfr " < 0x60\n\tout " sfr " - 0x20, " reg "\n\t.else\n\tsts " sfr ", " reg "\n\t.endif\n\t"

ISR(MCU_UART_UDRE_vect, ISR_NAKED)
{
	__asm__ __volatile__(
		"push r30\n\t"
		"in r30, __SREG__\n\t"
		"out %[keep], r30\n\t"
		"push r31\n\t"
		"lds r30, %[tail]\n\t"
		"ldi r31, 0\n\t"
		"subi r30, lo8(-(%[buf]))\n\t"
		"sbci r31, hi8(-(%[buf]))\n\t"
		"ld r31, Z\n\t"
		TX_IO_STORE("%[udr]", "r31")
		"subi r30, lo8(%[buf] - 1)\n\t"	/* the tail + 1 */
		"andi r30, %[mask]\n\t"
		"sts %[tail], r30\n\t"
		"lds r31, %[head]\n\t"
		"cp r30, r31\n\t"
		"brne 1f\n\t"
		".if %[ucsrb] < 0x40\n\t"
		"cbi %[ucsrb] - 0x20, %[udrie]\n\t"
		".else\n\t"
		"lds r30, %[ucsrb]\n\t"
		"andi r30, ~(1 << %[udrie])\n\t"
		"sts %[ucsrb], r30\n\t"
		".endif\n"
		"1:\n\t"
		"pop r31\n\t"
		"in r30, %[keep]\n\t"
		"out __SREG__, r30\n\t"
		"pop r30\n\t"
		"reti\n"
		: : [keep] "I" (ISR_KEEP), [udr] "n" (_SFR_MEM_ADDR(MCU_UDR)), [ucsrb] "n" (_SFR_MEM_ADDR(MCU_UCSRB)),
		[udrie] "n" (UDRIE), [tail] "i" (&uart.tx_tail),
		[head] "i" (&uart.tx_head), [buf] "i" (uart.tx), [mask] "n" (UART_TX_SIZE - 1));
}

/* The ring's new head stored, the bytes before it in place. UDRIE still
 * on: the interrupt sees the new head before it could find the ring empty.
 * Off: the ring was empty, or the interrupt emptied it since, before the
 * head was stored (the bytes wait) or after (they were sent); no interrupt
 * runs now to move the tail, so the tail tells which. No atomic block:
 * every byte but a reply's first two takes this path. */
static inline __attribute__((always_inline)) void tx_publish(uint8_t head)
{
	/* the bytes stored before the head that tells of them: the ring's
	 * bytes are not volatile, so the compiler is told (it was the atomic
	 * block's barrier) */
	__asm__ __volatile__("" : : : "memory");
	uart.tx_head = head;
	if (!(MCU_UCSRB & _BV(UDRIE)) && uart.tx_tail != head) {
		MCU_UCSRB |= _BV(UDRIE);
	}
}

/* UDRIE off (the ring is empty and UDR the main loop's) and UDR free: C
 * goes straight into it (true). A reply's first two bytes do (the shift
 * register takes the first at once, the buffer the second). */
static inline __attribute__((always_inline)) bool tx_direct(uint8_t c)
{
	if (!(MCU_UCSRB & _BV(UDRIE)) && (MCU_UCSRA & _BV(UDRE))) {
		MCU_UDR = c;
		return true;
	}
	return false;
}

void uart_putc(uint8_t c)
{
	if (tx_direct(c)) {
		return;
	}
	uint8_t head = uart.tx_head;
	uint8_t next = (uint8_t)((head + 1) & (UART_TX_SIZE - 1));
	if (__builtin_expect(next == uart.tx_tail, 0)) {
		/* Full: the UDRE interrupt frees a slot per byte sent. The
		 * watchdog is fed only when one did (progress): a stuck UDRE
		 * interrupt must end in a reset, not spin here fed. */
		while (next == uart.tx_tail) {  /* profile: idle */
		}
		wdt_reset();
	}
	uart.tx[head] = c;
	tx_publish(next);
}

/* Apart, so that uart_put2()'s own path keeps no register. */
static __attribute__((noinline)) void put2_each(uint8_t a, uint8_t b)
{
	uart_putc(a);
	uart_putc(b);
}

void uart_put2(uint8_t a, uint8_t b)
{
	if (tx_direct(a)) {
		uart_putc(b);
		return;
	}
	uint8_t head = uart.tx_head;

	/* Both into the ring when it has room for two; else one at a time. */
	if ((uint8_t)((uart.tx_tail - head - 1) & (UART_TX_SIZE - 1)) >= 2) {
		uart.tx[head] = a;
		head = (uint8_t)((head + 1) & (UART_TX_SIZE - 1));
		uart.tx[head] = b;
		tx_publish((uint8_t)((head + 1) & (UART_TX_SIZE - 1)));
		return;
	}
	put2_each(a, b);
}
