/* The serial gateway front end: UART characters in, replies out. */
#include "firmware/front.h"

#include <avr/wdt.h>
#include <util/atomic.h>

#include "firmware/sys.h"
#include "firmware/twi_master.h"
#include "firmware/uart.h"
#include "serialgate/sg_exec.h"
#include "serialgate/sg_parse.h"
#include "serialgate/sg_rx.h"

_Static_assert(SG_RX_MARK_LOST == SG_CHAR_LOST && SG_RX_MARK_END_LOST == SG_CHAR_END_LOST &&
	SG_RX_MARK_END_EMPTY == SG_CHAR_END_EMPTY, "receive ring and parser agree on the marks");

static sg_parser_t parser;

void sg_out(uint8_t c)
{
	uart_putc(c);
}

void sg_out2(uint8_t a, uint8_t b)
{
	uart_put2(a, b);
}

void sg_lost_answered(void)
{
	wdt_reset();  /* progress: a reply out (sg_exec.h) */
}

void uart_received(uint8_t c)
{
	sg_rx_put(c);
}

/* Nothing received, no line begun: at start-up, and at a new autobaud
 * rate (what the ring and the parser hold came at the old one). One
 * function for both: 10 bytes less than inlined twice. */
static void front_line_reset(void)
{
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		sg_rx_init();
	}
	sg_parse_init(&parser);
}

void front_init(void)
{
	uart_init();
	twi_init();
	front_line_reset();  /* interrupts are still off (main()) */
	sg_exec_init();
}

void front_poll(void)
{
	/* A character is looked for a while (16 looks, a few hundred
	 * cycles: nothing to autobaud's watch of the pin) before the idle
	 * work: a request's end is taken within a few cycles of its
	 * arrival, not after the rest of an idle round. */
	uint8_t tail;
	uint8_t spin = 16;
	do {
		tail = sg_rx.tail;                      /* profile: idle */
	} while (tail == sg_rx.head && --spin);  /* profile: idle */
	if (tail == sg_rx.head) {
		uart_rx_flush();
		if (!sg_rx_losing()) {
			if (uart_line_poll()) {
				front_line_reset();  /* a new rate (autobaud) */
			}
			/* Idle: the failsafe's turn. Not on the busy path, where
			 * the M32-D's streamed servo writes have no cycle to spare
			 * (characters always leave the loop idle in between). */
			sys_poll();
			twi_idle();
			return;
		}
		ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
			sg_rx_close();
		}
		if (tail == sg_rx.head) {
			return;
		}
	}
	uint8_t c = sg_rx.buf[tail];
	/* c >= ' ' first: a line's end (the latency's character) goes to
	 * sg_parse_char() at once. An I2C request's first S and its common
	 * run (spaces, digits, a frame's S and P), what the ring holds of
	 * them, are taken in one loop (sg_parse_run()); the character it
	 * stops at, or anything else, goes through sg_parse_char(). */
	if (c >= ' ') {
		uint8_t to = sg_parse_run(&parser, sg_rx.buf, tail, &sg_rx.head);
		if (to != tail) {
			sg_rx.tail = to;
			return;
		}
	}
	sg_rx.tail = (uint8_t)(tail + 1);
	sg_event_t ev = sg_parse_char(&parser, c);
	if (ev == SG_REQUEST) {
		SYS_HEARD();  /* any request line keeps the link alive */
		if (parser.err == SG_OK) {
			uart_line_confirm();	/* a good request proves the rate */
		}
		sg_exec(&parser);
	} else if (ev == SG_LOST) {
		SYS_HEARD();
		sg_exec_lost(&parser);
	}
}
