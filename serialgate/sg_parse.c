#include "serialgate/sg_parse.h"

#include <stdbool.h>

static __attribute__((noinline)) sg_event_t fail(sg_parser_t *p, uint8_t err)
{
	if (p->err == SG_OK) {
		p->err = err;
	}
	p->state = SG_ST_ERROR;
	return SG_MORE;
}

/* The room checks are 8-bit sums and differences. */
_Static_assert(SG_BUF_SIZE <= 255 && SG_REPLY_MAX <= 255, "the room checks' 8 bits");

/* A write frame's data byte at buf[at] (at: nbytes), with room for it. */
static inline __attribute__((always_inline)) void take_data(sg_parser_t *p, uint8_t at, uint8_t b)
{
	p->buf[at] = b;
	p->nbytes = (uint8_t)(at + 1);
	p->buf[p->frame + 1]++;
	p->reply_len++;
}

/* A frame's address byte: a read frame's count or a write's data next. */
static inline __attribute__((always_inline)) uint8_t take_address(sg_parser_t *p, uint8_t b)
{
	uint8_t at = p->frame;
	uint8_t state = (b & 1) ? SG_ST_RCOUNT : SG_ST_WDATA;

	p->buf[at] = b;
	p->buf[at + 1] = 0;
	p->nbytes = (uint8_t)(at + 2);
	p->state = state;
	return state;
}

sg_event_t sg_parse_frame(sg_parser_t *p)
{
	/* room for the frame's two bytes and its two reply characters, in 8 bits */
	if (p->nbytes > SG_BUF_SIZE - 2 || p->reply_len > SG_REPLY_MAX - 2) {
		return fail(p, SG_ERR_DATA);
	}
	p->frame = p->nbytes;
	p->reply_len = (uint8_t)(p->reply_len + 2);  /* "SW" or "SR" */
	p->state = SG_ST_ADDR;
	return SG_MORE;
}

sg_event_t sg_parse_byte(sg_parser_t *p, uint8_t b)
{
	switch (p->state) {
	case SG_ST_ARGS:
		p->buf[p->nbytes++] = b;
		if (p->cmd == SG_CMD_LOCAL) {
			if ((b & 0xFE) == 0) {
				return fail(p, SG_ERR_DATA);
			}
			p->state = SG_ST_DONE;
		} else if (p->nbytes == 2) {
			if (p->buf[0] == 0 && p->buf[1] == 0) {
				return fail(p, SG_ERR_DATA);
			}
			p->state = SG_ST_DONE;
		}
		return SG_MORE;
	case SG_ST_ADDR:
		take_address(p, b);
		return SG_MORE;
	case SG_ST_WDATA:
		if (p->nbytes >= SG_BUF_SIZE || p->reply_len >= SG_REPLY_MAX) {  /* room for a byte and its reply character */
			return fail(p, SG_ERR_DATA);
		}
		take_data(p, p->nbytes, b);
		return SG_MORE;
	case SG_ST_RCOUNT:
		/* room for b bytes and their 2 * b reply characters, in 8 bits
		 * (nbytes <= SG_BUF_SIZE, reply_len <= SG_REPLY_MAX always) */
		if (b == 0 || b > (uint8_t)(SG_BUF_SIZE - p->nbytes) ||
		    b > (uint8_t)((SG_REPLY_MAX - p->reply_len) >> 1)) {
			return fail(p, SG_ERR_DATA);
		}
		p->buf[p->frame + 1] = b;
		p->nbytes = (uint8_t)(p->nbytes + b);
		p->reply_len = (uint8_t)(p->reply_len + 2u * b);
		p->state = SG_ST_RDONE;
		return SG_MORE;
	default:
		return fail(p, SG_ERR_INTERNAL);
	}
}

/* A hex digit, in any state after the command letter. */
static sg_event_t take_digit(sg_parser_t *p, uint8_t d)
{
	if ((uint8_t)(p->state - SG_ST_ARGS) > SG_ST_RCOUNT - SG_ST_ARGS) {
		/* SG_ST_DONE, SG_ST_RDONE: a byte where none may stand */
		return fail(p, SG_ERR_DATA);
	}
	if (p->hi == SG_NO_DIGIT) {
		p->hi = d;
		return SG_MORE;
	}
	uint8_t b = (uint8_t)(sg_nibble_up(p->hi) | d);
	p->hi = SG_NO_DIGIT;
	return sg_parse_byte(p, b);
}

/* An I2C request's S: its first frame. */
static inline __attribute__((always_inline)) sg_event_t begin_i2c(sg_parser_t *p)
{
	p->cmd = SG_CMD_I2C;
	p->reply_len = 1;  /* the closing "P" */
	return sg_parse_frame(p);
}

/* A one-letter command: V and X take nothing more (SG_ST_DONE), L and C
 * optional bytes (SG_ST_ARGS). */
static sg_event_t begin_line_command(sg_parser_t *p, uint8_t cmd, uint8_t state)
{
	p->cmd = cmd;
	p->state = state;
	return SG_MORE;
}

static sg_event_t begin_command(sg_parser_t *p, uint8_t c)
{
	switch (c | 0x20) {
	case 'v':
		return begin_line_command(p, SG_CMD_VERSION, SG_ST_DONE);
	case 'x':
		return begin_line_command(p, SG_CMD_CLEAR, SG_ST_DONE);
	case 'l':
		return begin_line_command(p, SG_CMD_LOCAL, SG_ST_ARGS);
	case 'c':
		return begin_line_command(p, SG_CMD_CLOCK, SG_ST_ARGS);
	case 's':
		return begin_i2c(p);
	default:
		return fail(p, SG_ERR_COMMAND);
	}
}

static sg_event_t end_line(sg_parser_t *p)
{
	uint8_t state = p->state;
	p->state = SG_ST_BEGIN;
	switch (state) {
	case SG_ST_BEGIN:
	case SG_ST_LEAD:
	case SG_ST_COMMENT:
		return SG_IGNORED;
	case SG_ST_ERROR:
	case SG_ST_DONE:
		break;
	case SG_ST_ARGS:
		if (p->hi != SG_NO_DIGIT) {
			p->err = SG_ERR_HEX;
		} else if (p->cmd == SG_CMD_CLOCK && p->nbytes == 1) {
			p->err = SG_ERR_DATA;
		}
		break;
	default:  /* inside an I2C request */
		p->err = (p->hi != SG_NO_DIGIT) ? SG_ERR_HEX : SG_ERR_NO_P;
		break;
	}
	return SG_REQUEST;
}

/* A byte of the record after SG_CHAR_LOST: the line in progress is gone
 * (its end was lost, and with it its reply if it was a request, which the
 * record counts); each lost request is answered ERROR 04. */
static sg_event_t lost_run(sg_parser_t *p, uint8_t c)
{
	if (p->lost_info == 2) {
		p->lost = c;
		p->lost_info = 1;
		return SG_MORE;
	}
	p->lost |= (uint16_t)c << 8;
	sg_parse_init(p);
	return p->lost ? SG_LOST : SG_IGNORED;
}

/* Out of line: inlined at each of its callers it cost ~70 bytes, for a
 * call once a line. */
__attribute__((noinline)) void sg_parse_init(sg_parser_t *p)
{
	p->state = SG_ST_BEGIN;
	p->err = SG_OK;
	p->cmd = SG_CMD_NONE;
	p->len = 0;
	p->hi = SG_NO_DIGIT;
	p->nbytes = 0;
	p->frame = 0;
	p->reply_len = 0;
	p->lost_info = 0;
}

sg_event_t sg_parse_char(sg_parser_t *p, uint8_t c)
{
	if (p->lost_info) {
		return lost_run(p, c);
	}
	if (c == '\r' || c == '\n') {
		return end_line(p);
	}
	if (c == SG_CHAR_LOST) {
		p->lost_info = 2;
		return SG_MORE;
	}
	if (c == SG_CHAR_END_LOST || c == SG_CHAR_END_EMPTY) {
		/* the end of a line that lost characters: the receive ring knew
		 * what the parser cannot (the lost part), so it decides */
		p->state = SG_ST_BEGIN;
		if (c == SG_CHAR_END_EMPTY) {
			return SG_IGNORED;
		}
		p->err = SG_ERR_DATA;
		return SG_REQUEST;
	}
	if (p->state == SG_ST_BEGIN) {
		sg_parse_init(p);
	}
	if (p->state == SG_ST_COMMENT || p->state == SG_ST_ERROR) {
		return SG_MORE;
	}
	if (p->len <= SG_LINE_MAX) {
		p->len++;  /* stops at one over the limit */
	}
	bool blank = c == ' ' && (p->state == SG_ST_BEGIN || p->state == SG_ST_LEAD);
	if (p->len > SG_LINE_MAX && !blank) {
		/* over the limit; a line of nothing but spaces is empty, however
		 * long (no reply) */
		return fail(p, SG_ERR_DATA);
	}
	uint8_t d = sg_hex_value(c);
	if (p->hi != SG_NO_DIGIT && d == SG_NO_DIGIT) {
		return fail(p, SG_ERR_HEX);  /* a byte with one digit */
	}
	if (c == ' ') {
		if (p->state == SG_ST_BEGIN) {
			p->state = SG_ST_LEAD;
		}
		return SG_MORE;
	}
	switch (p->state) {
	case SG_ST_BEGIN:
		if (c == '#') {
			p->state = SG_ST_COMMENT;
			return SG_MORE;
		}
		return begin_command(p, c);
	case SG_ST_LEAD:
		return begin_command(p, c);
	case SG_ST_DONE:
		return fail(p, SG_ERR_DATA);
	default:
		break;
	}
	if (d != SG_NO_DIGIT) {
		return take_digit(p, d);
	}
	uint8_t lc = c | 0x20;
	if (lc == 's' && (p->state == SG_ST_WDATA || p->state == SG_ST_RDONE)) {
		return sg_parse_frame(p);
	}
	if (lc == 'p' && (p->state == SG_ST_WDATA || p->state == SG_ST_RDONE)) {
		p->state = SG_ST_DONE;
		return SG_MORE;
	}
	if ((lc == 's' || lc == 'p') && p->state == SG_ST_RCOUNT) {
		return fail(p, SG_ERR_DATA);  /* a read frame without its count */
	}
	return fail(p, SG_ERR_HEX);  /* not a hex digit where a byte is expected */
}

uint8_t sg_parse_run(sg_parser_t *p, const uint8_t *ring, uint8_t tail, const volatile uint8_t *head)
{
	uint8_t len = p->len;
	uint8_t state = p->state;

	/* not in a lost run's record, within the line's room, a state the
	 * run takes characters in (it may leave it only where a byte or a
	 * frame ends: the state is looked at there) */
	if (p->lost_info || len >= SG_LINE_MAX) {
		return tail;
	}
	if (state == SG_ST_BEGIN && tail != *head && (ring[tail] | 0x20) == 's') {
		/* an I2C request's first character, as sg_parse_char() takes it */
		sg_parse_init(p);
		begin_i2c(p);
		state = p->state;
		len = 1;
		p->len = len;
		tail++;
	}
	if (!sg_parse_in_run(p)) {
		return tail;
	}
	uint8_t hi = p->hi;
	/* the index to stop at: the line's room, or the ring's end (0: the
	 * next run goes on from buf[0]) */
	uint8_t stop = (uint8_t)(tail + (uint8_t)(SG_LINE_MAX - len));
	if (stop < tail) {
		stop = 0;
	}
	const uint8_t *const from = ring + tail;
	const uint8_t *end = from;
	const uint8_t *q = from;
	for (;; q++) {
		if (q == end) {
			/* all taken that had come (at the start: none): what came
			 * since, up to stop. Looked at again here, not left to
			 * the next call: a call's start and end cost ~60 cycles,
			 * a few times a request at 460800 baud. */
			uint8_t at = (uint8_t)(q - ring);
			uint8_t n = (uint8_t)(*head - at);
			uint8_t room = (uint8_t)(stop - at);

			if (n > room) {
				n = room;
			}
			if (!n) {
				break;
			}
			end = q + n;
		}
		uint8_t c = *q;

		if (c == ' ') {
			if (hi != SG_NO_DIGIT) {
				break;
			}
			continue;
		}
		uint8_t d = sg_hex_value(c);  /* SG_NO_DIGIT for a control character or a mark */
		if (d != SG_NO_DIGIT) {
			if (state > SG_ST_RCOUNT) {
				break;
			}
			if (hi == SG_NO_DIGIT) {
				hi = d;
				continue;
			}
			uint8_t b = (uint8_t)(sg_nibble_up(hi) | d);
			uint8_t at = p->nbytes;

			hi = SG_NO_DIGIT;
			/* sg_parse_byte()'s common cases in place (with its room
			 * check for a data byte): a write frame's data byte, a
			 * frame's address */
			if (state == SG_ST_WDATA && at < SG_BUF_SIZE && p->reply_len < SG_REPLY_MAX) {
				take_data(p, at, b);
			} else if (state == SG_ST_ADDR) {
				state = take_address(p, b);
			} else {
				/* it uses neither len nor hi */
				sg_parse_byte(p, b);
				state = p->state;
				if (!sg_parse_in_run(p)) {
					q++;  /* taken: an error ends the run */
					break;
				}
			}
			continue;
		}
		if (hi != SG_NO_DIGIT || (state != SG_ST_WDATA && state != SG_ST_RDONE)) {
			break;
		}
		c |= 0x20;
		if (c == 'p') {
			state = SG_ST_DONE;
			p->state = state;
		} else if (c == 's') {
			sg_parse_frame(p);
			state = p->state;
			if (!sg_parse_in_run(p)) {
				q++;  /* taken: no room for the frame */
				break;
			}
		} else {
			break;
		}
	}
	/* each character taken is one of the line's */
	uint8_t taken = (uint8_t)(q - from);
	p->len = (uint8_t)(len + taken);
	p->hi = hi;
	return (uint8_t)(tail + taken);
}
