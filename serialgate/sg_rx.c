#include "serialgate/sg_rx.h"

/* What is known of the line being received, stored or lost. */
#define LINE_STARTED 0x01  /* a character since the last line end */
#define LINE_CONTENT 0x02  /* something but a space */
_Static_assert((LINE_STARTED | LINE_CONTENT) == SG_RX_LINE_PLAIN, "sg_rx.h's plain line");
#define LINE_COMMENT 0x04  /* its first character is '#' */
#define LINE_LOST    0x08  /* characters of it were lost */

_Static_assert(SG_RX_SIZE == 256, "indices are uint8_t and wrap at 256");

struct sg_rx sg_rx;

void sg_rx_init(void)
{
	sg_rx.head = 0;
	sg_rx.tail = 0;
	sg_rx.losing = 0;
	sg_rx.line = 0;
}

/* The run of lost characters is over: its record, if a line ended in it.
 * Inlined: a call from the receive interrupt would make it save every
 * call-clobbered register, on every character. Not with autobaud, whose
 * receive interrupt saves them anyway (it calls uart_line_rx() on every
 * character): there one copy serves it and sg_rx_close() (~50 bytes). */
#ifdef ORFA_BAUD
#define END_RUN_INLINE inline __attribute__((always_inline))
#else
#define END_RUN_INLINE __attribute__((noinline))
#endif
static END_RUN_INLINE uint8_t end_run(uint8_t head)
{
	if (sg_rx.ends_lost) {
		sg_rx.buf[head] = SG_RX_MARK_LOST;
		sg_rx.buf[(uint8_t)(head + 1)] = (uint8_t)sg_rx.requests_lost;
		sg_rx.buf[(uint8_t)(head + 2)] = (uint8_t)(sg_rx.requests_lost >> 8);
		head = (uint8_t)(head + 3);
		sg_rx.head = head;
	}
	sg_rx.losing = 0;
	return head;
}

/* A character the receive interrupt's fast path leaves (sg_rx_put()). */
static inline __attribute__((always_inline)) void put_slow(uint8_t c, uint8_t head)
{
	uint8_t room = (uint8_t)(sg_rx.tail - head - 1);

	if (sg_rx.losing) {
		if (room > SG_RX_RECORD) {
			head = end_run(head);  /* room for the record and this byte */
		}
	} else if (room <= SG_RX_RECORD) {
		sg_rx.losing = 1;  /* the line below gets LINE_LOST or ends: never plain (sg_rx.h) */
		sg_rx.ends_lost = 0;
		sg_rx.requests_lost = 0;
	}

	uint8_t line = sg_rx.line;
	if (c == '\r' || c == '\n') {
		bool request = (line & (LINE_CONTENT | LINE_COMMENT)) == LINE_CONTENT;
		sg_rx.line = 0;
		if (sg_rx.losing) {
			sg_rx.ends_lost = 1;
			if (request && sg_rx.requests_lost != UINT16_MAX) {
				sg_rx.requests_lost++;
			}
			return;
		}
		if (line & LINE_LOST) {
			c = request ? SG_RX_MARK_END_LOST : SG_RX_MARK_END_EMPTY;
		}
	} else {
		if (!(line & LINE_STARTED)) {
			line |= LINE_STARTED;
			if (c == '#') {
				line |= LINE_COMMENT;
			}
		}
		if (c != ' ') {
			line |= LINE_CONTENT;
		}
		if (sg_rx.losing) {
			sg_rx.line = line | LINE_LOST;
			return;
		}
		sg_rx.line = line;
		if (c >= SG_RX_MARK_LOST) {
			c = 0x7F;
		}
	}
	sg_rx.buf[head] = c;
	sg_rx.head = (uint8_t)(head + 1);
}

void sg_rx_put(uint8_t c)
{
	/* A fixed rate's receive interrupt stores a request's common
	 * characters itself (its fast path, firmware/uart.c, sg_rx.h's rule)
	 * and brings the rest here; autobaud's brings every character. */
	put_slow(c, sg_rx.head);
}

int16_t sg_rx_get(void)
{
	uint8_t tail = sg_rx.tail;
	if (tail == sg_rx.head) {
		return -1;
	}
	uint8_t c = sg_rx.buf[tail];
	sg_rx.tail = (uint8_t)(tail + 1);
	return c;
}

bool sg_rx_losing(void)
{
	return sg_rx.losing;
}

void sg_rx_close(void)
{
	if (sg_rx.losing && sg_rx.tail == sg_rx.head) {
		end_run(sg_rx.head);
	}
}
