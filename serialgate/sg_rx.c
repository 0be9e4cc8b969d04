#include "serialgate/sg_rx.h"

/* What is known of the line being received, stored or lost. */
#define LINE_STARTED 0x01  /* a character since the last line end */
#define LINE_CONTENT 0x02  /* something but a space */
#define LINE_COMMENT 0x04  /* its first character is '#' */
#define LINE_LOST    0x08  /* characters of it were lost */

_Static_assert(SG_RX_SIZE == 256, "indices are uint8_t and wrap at 256");

static struct {
	uint8_t buf[SG_RX_SIZE];
	volatile uint8_t head;     /* written by the interrupt */
	volatile uint8_t tail;     /* written by the main loop */
	volatile uint8_t losing;   /* characters are being lost */
	uint8_t ends_lost;         /* a line end was lost in this run */
	uint16_t requests_lost;    /* requests whose end was lost in this run */
	uint8_t line;              /* LINE_* */
} rx;

void sg_rx_init(void)
{
	rx.head = 0;
	rx.tail = 0;
	rx.losing = 0;
	rx.line = 0;
}

/* The run of lost characters is over: its record, if a line ended in it.
 * Inlined: a call from the receive interrupt would make it save every
 * call-clobbered register, on every character. */
static inline __attribute__((always_inline)) uint8_t end_run(uint8_t head)
{
	if (rx.ends_lost) {
		rx.buf[head] = SG_RX_MARK_LOST;
		rx.buf[(uint8_t)(head + 1)] = (uint8_t)rx.requests_lost;
		rx.buf[(uint8_t)(head + 2)] = (uint8_t)(rx.requests_lost >> 8);
		head = (uint8_t)(head + 3);
		rx.head = head;
	}
	rx.losing = 0;
	return head;
}

/* A line end, or any character while the ring is full or nearly. */
static inline __attribute__((always_inline)) void put_slow(uint8_t c, uint8_t head)
{
	uint8_t room = (uint8_t)(rx.tail - head - 1);

	if (rx.losing) {
		if (room > SG_RX_RECORD) {
			head = end_run(head);  /* room for the record and this byte */
		}
	} else if (room <= SG_RX_RECORD) {
		rx.losing = 1;
		rx.ends_lost = 0;
		rx.requests_lost = 0;
	}

	uint8_t line = rx.line;
	if (c == '\r' || c == '\n') {
		bool request = (line & (LINE_CONTENT | LINE_COMMENT)) == LINE_CONTENT;
		rx.line = 0;
		if (rx.losing) {
			rx.ends_lost = 1;
			if (request && rx.requests_lost != UINT16_MAX) {
				rx.requests_lost++;
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
		if (rx.losing) {
			rx.line = line | LINE_LOST;
			return;
		}
		rx.line = line;
		if (c >= SG_RX_MARK_LOST) {
			c = 0x7F;
		}
	}
	rx.buf[head] = c;
	rx.head = (uint8_t)(head + 1);
}

void sg_rx_put(uint8_t c)
{
	uint8_t head = rx.head;
	uint8_t line = rx.line;

	/* The common cases first, room to spare: a character inside a line,
	 * and the end of a line that lost nothing (on the latency path of
	 * every request). */
	if (!rx.losing && (uint8_t)(rx.tail - head - 1) > SG_RX_RECORD) {
		if (c == '\r' || c == '\n') {
			if (!(line & LINE_LOST)) {
				rx.line = 0;
				rx.buf[head] = c;
				rx.head = (uint8_t)(head + 1);
				return;
			}
		} else if (line & LINE_STARTED) {
			if (c != ' ') {
				rx.line = line | LINE_CONTENT;
			}
			if (c >= SG_RX_MARK_LOST) {
				c = 0x7F;
			}
			rx.buf[head] = c;
			rx.head = (uint8_t)(head + 1);
			return;
		}
	}
	put_slow(c, head);
}

int16_t sg_rx_get(void)
{
	uint8_t tail = rx.tail;
	if (tail == rx.head) {
		return -1;
	}
	uint8_t c = rx.buf[tail];
	rx.tail = (uint8_t)(tail + 1);
	return c;
}

bool sg_rx_losing(void)
{
	return rx.losing;
}

void sg_rx_close(void)
{
	if (rx.losing && rx.tail == rx.head) {
		end_run(rx.head);
	}
}
