#include "serialgate/sg_parse.h"

#include <stdbool.h>

enum {
	ST_BEGIN,    /* first character of a line */
	ST_LEAD,     /* only spaces so far */
	ST_COMMENT,  /* a '#' line */
	ST_ARGS,     /* L / C: optional bytes */
	ST_ADDR,     /* I2C: a frame's address byte expected */
	ST_WDATA,    /* I2C write frame: data bytes, S or P */
	ST_RCOUNT,   /* I2C read frame: the count byte expected */
	ST_RDONE,    /* I2C read frame complete: S or P */
	ST_DONE,     /* complete command: only spaces may follow */
	ST_ERROR,    /* discard the rest of the line */
};

#define NO_DIGIT 0xFF

static uint8_t hex_value(uint8_t c)
{
	if (c >= '0' && c <= '9') {
		return (uint8_t)(c - '0');
	}
	c |= 0x20;  /* lower case */
	if (c >= 'a' && c <= 'f') {
		return (uint8_t)(c - 'a' + 10);
	}
	return NO_DIGIT;
}

static __attribute__((noinline)) sg_event_t fail(sg_parser_t *p, uint8_t err)
{
	if (p->err == SG_OK) {
		p->err = err;
	}
	p->state = ST_ERROR;
	return SG_MORE;
}

static bool room(sg_parser_t *p, uint16_t bytes, uint16_t reply_chars)
{
	return p->nbytes + bytes <= SG_BUF_SIZE && p->reply_len + reply_chars <= SG_REPLY_MAX;
}

static sg_event_t start_frame(sg_parser_t *p)
{
	if (!room(p, 2, 2)) {
		return fail(p, SG_ERR_DATA);
	}
	p->frame = p->nbytes;
	p->reply_len = (uint8_t)(p->reply_len + 2);  /* "SW" or "SR" */
	p->state = ST_ADDR;
	return SG_MORE;
}

/* A complete byte in a state that takes one. */
static sg_event_t take_byte(sg_parser_t *p, uint8_t b)
{
	switch (p->state) {
	case ST_ARGS:
		p->buf[p->nbytes++] = b;
		if (p->cmd == SG_CMD_LOCAL) {
			if ((b & 0xFE) == 0) {
				return fail(p, SG_ERR_DATA);
			}
			p->state = ST_DONE;
		} else if (p->nbytes == 2) {
			if (p->buf[0] == 0 && p->buf[1] == 0) {
				return fail(p, SG_ERR_DATA);
			}
			p->state = ST_DONE;
		}
		return SG_MORE;
	case ST_ADDR:
		p->buf[p->frame] = b;
		p->buf[p->frame + 1] = 0;
		p->nbytes = (uint8_t)(p->frame + 2);
		p->state = (b & 1) ? ST_RCOUNT : ST_WDATA;
		return SG_MORE;
	case ST_WDATA:
		if (!room(p, 1, 1)) {
			return fail(p, SG_ERR_DATA);
		}
		p->buf[p->nbytes++] = b;
		p->buf[p->frame + 1]++;
		p->reply_len++;
		return SG_MORE;
	case ST_RCOUNT:
		if (b == 0 || !room(p, b, 2u * b)) {
			return fail(p, SG_ERR_DATA);
		}
		p->buf[p->frame + 1] = b;
		p->nbytes = (uint8_t)(p->nbytes + b);
		p->reply_len = (uint8_t)(p->reply_len + 2u * b);
		p->state = ST_RDONE;
		return SG_MORE;
	default:
		return fail(p, SG_ERR_INTERNAL);
	}
}

/* A hex digit, in any state after the command letter. */
static sg_event_t take_digit(sg_parser_t *p, uint8_t d)
{
	switch (p->state) {
	case ST_ARGS:
	case ST_ADDR:
	case ST_WDATA:
	case ST_RCOUNT:
		break;
	default:  /* ST_DONE, ST_RDONE: a byte where none may stand */
		return fail(p, SG_ERR_DATA);
	}
	if (p->hi == NO_DIGIT) {
		p->hi = d;
		return SG_MORE;
	}
	uint8_t b = (uint8_t)(p->hi << 4 | d);
	p->hi = NO_DIGIT;
	return take_byte(p, b);
}

/* A one-letter command: V and X take nothing more (ST_DONE), L and C
 * optional bytes (ST_ARGS). */
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
		return begin_line_command(p, SG_CMD_VERSION, ST_DONE);
	case 'x':
		return begin_line_command(p, SG_CMD_CLEAR, ST_DONE);
	case 'l':
		return begin_line_command(p, SG_CMD_LOCAL, ST_ARGS);
	case 'c':
		return begin_line_command(p, SG_CMD_CLOCK, ST_ARGS);
	case 's':
		p->cmd = SG_CMD_I2C;
		p->reply_len = 1;  /* the closing "P" */
		return start_frame(p);
	default:
		return fail(p, SG_ERR_COMMAND);
	}
}

static sg_event_t end_line(sg_parser_t *p)
{
	uint8_t state = p->state;
	p->state = ST_BEGIN;
	switch (state) {
	case ST_BEGIN:
	case ST_LEAD:
	case ST_COMMENT:
		return SG_IGNORED;
	case ST_ERROR:
	case ST_DONE:
		break;
	case ST_ARGS:
		if (p->hi != NO_DIGIT) {
			p->err = SG_ERR_HEX;
		} else if (p->cmd == SG_CMD_CLOCK && p->nbytes == 1) {
			p->err = SG_ERR_DATA;
		}
		break;
	default:  /* inside an I2C request */
		p->err = (p->hi != NO_DIGIT) ? SG_ERR_HEX : SG_ERR_NO_P;
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

void sg_parse_init(sg_parser_t *p)
{
	p->state = ST_BEGIN;
	p->err = SG_OK;
	p->cmd = SG_CMD_NONE;
	p->len = 0;
	p->hi = NO_DIGIT;
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
		p->state = ST_BEGIN;
		if (c == SG_CHAR_END_EMPTY) {
			return SG_IGNORED;
		}
		p->err = SG_ERR_DATA;
		return SG_REQUEST;
	}
	if (p->state == ST_BEGIN) {
		sg_parse_init(p);
	}
	if (p->state == ST_COMMENT || p->state == ST_ERROR) {
		return SG_MORE;
	}
	if (p->len <= SG_LINE_MAX) {
		p->len++;  /* stops at one over the limit */
	}
	bool blank = c == ' ' && (p->state == ST_BEGIN || p->state == ST_LEAD);
	if (p->len > SG_LINE_MAX && !blank) {
		/* over the limit; a line of nothing but spaces is empty, however
		 * long (no reply) */
		return fail(p, SG_ERR_DATA);
	}
	uint8_t d = hex_value(c);
	if (p->hi != NO_DIGIT && d == NO_DIGIT) {
		return fail(p, SG_ERR_HEX);  /* a byte with one digit */
	}
	if (c == ' ') {
		if (p->state == ST_BEGIN) {
			p->state = ST_LEAD;
		}
		return SG_MORE;
	}
	switch (p->state) {
	case ST_BEGIN:
		if (c == '#') {
			p->state = ST_COMMENT;
			return SG_MORE;
		}
		return begin_command(p, c);
	case ST_LEAD:
		return begin_command(p, c);
	case ST_DONE:
		return fail(p, SG_ERR_DATA);
	default:
		break;
	}
	if (d != NO_DIGIT) {
		return take_digit(p, d);
	}
	uint8_t lc = c | 0x20;
	if (lc == 's' && (p->state == ST_WDATA || p->state == ST_RDONE)) {
		return start_frame(p);
	}
	if (lc == 'p' && (p->state == ST_WDATA || p->state == ST_RDONE)) {
		p->state = ST_DONE;
		return SG_MORE;
	}
	if ((lc == 's' || lc == 'p') && p->state == ST_RCOUNT) {
		return fail(p, SG_ERR_DATA);  /* a read frame without its count */
	}
	return fail(p, SG_ERR_HEX);  /* not a hex digit where a byte is expected */
}
