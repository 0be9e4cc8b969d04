/*
 * Request lines and reply lines of the gateway protocol (docs/protocol.md).
 * Requests are written without spaces ("SAA0000SAB01P"), so the most fits
 * in the 128 characters.
 */
#include "orfa_line.h"

#include <string.h>

#include "serialgate/sg_parse.h"

/* The limits are the firmware's; a drift stops the build. */
#if ORFA_REQUEST_MAX != SG_LINE_MAX || ORFA_REPLY_MAX != SG_REPLY_MAX
#error "orfa_line.h's limits differ from serialgate/sg_parse.h"
#endif

static const char hexdig[] = "0123456789ABCDEF";

static void put_byte(orfa_req_t *r, uint8_t b)
{
	r->text[r->len++] = hexdig[b >> 4];
	r->text[r->len++] = hexdig[b & 0x0F];
}

static void put_end(orfa_req_t *r)
{
	r->text[r->len++] = '\n';
	r->text[r->len] = '\0';
	r->ended = 1;
}

void orfa_req_start(orfa_req_t *r)
{
	memset(r, 0, sizeof(*r));
	r->kind = ORFA_REQ_I2C;
	/* the closing "P" of both lines is counted from the start */
	r->reply_len = 1;
}

/* Room for a frame of `chars` request characters and `reply` reply
 * characters, the closing P being counted already in reply_len and here. */
static int room(orfa_req_t *r, size_t chars, size_t reply)
{
	if (r->error) {
		return r->error;
	}
	if (r->ended || r->kind != ORFA_REQ_I2C) {
		return ORFA_E_ARG;
	}
	if (r->nframes >= ORFA_FRAMES_MAX || r->len + chars + 1 > ORFA_REQUEST_MAX ||
	    r->reply_len + reply > ORFA_REPLY_MAX) {
		r->error = ORFA_E_LIMIT;
		return ORFA_E_LIMIT;
	}
	return ORFA_OK;
}

int orfa_req_write(orfa_req_t *r, uint8_t address, const uint8_t *buf, size_t len)
{
	size_t i;
	int rc;

	if (r == NULL || (buf == NULL && len > 0)) {
		return ORFA_E_ARG;
	}
	/* the length check comes first: len may be far over any limit */
	if (len > ORFA_REQUEST_MAX) {
		rc = room(r, ORFA_REQUEST_MAX + 1, 0);
	} else {
		rc = room(r, 3 + 2 * len, 2 + len);
	}
	if (rc != ORFA_OK) {
		return rc;
	}
	r->frames[r->nframes].address = address & 0xFE;
	r->frames[r->nframes].count = (uint8_t)len;
	r->nframes++;
	r->text[r->len++] = 'S';
	put_byte(r, address & 0xFE);
	for (i = 0; i < len; i++) {
		put_byte(r, buf[i]);
	}
	r->text[r->len] = '\0';
	r->reply_len += 2 + len;
	return ORFA_OK;
}

int orfa_req_read(orfa_req_t *r, uint8_t address, size_t count)
{
	int rc;

	if (r == NULL) {
		return ORFA_E_ARG;
	}
	if (count == 0) {
		/* the gateway's ERROR 04, caught before sending; the request as a
		 * whole is refused like any refused frame */
		if (r->error == ORFA_OK) {
			r->error = ORFA_E_ARG;
		}
		return ORFA_E_ARG;
	}
	rc = room(r, 5, count > ORFA_REPLY_MAX ? ORFA_REPLY_MAX + 1 : 2 + 2 * count);
	if (rc != ORFA_OK) {
		return rc;
	}
	r->frames[r->nframes].address = address | 1;
	r->frames[r->nframes].count = (uint8_t)count;
	r->nframes++;
	r->text[r->len++] = 'S';
	put_byte(r, address | 1);
	put_byte(r, (uint8_t)count);
	r->text[r->len] = '\0';
	r->reply_len += 2 + 2 * count;
	return ORFA_OK;
}

int orfa_req_end(orfa_req_t *r)
{
	if (r == NULL) {
		return ORFA_E_ARG;
	}
	if (r->error) {
		return r->error;
	}
	if (r->ended || r->kind != ORFA_REQ_I2C || r->nframes == 0) {
		return ORFA_E_ARG;
	}
	r->text[r->len++] = 'P';
	put_end(r);
	return ORFA_OK;
}

static int command(orfa_req_t *r, orfa_req_kind_t kind, char letter)
{
	if (r == NULL) {
		return ORFA_E_ARG;
	}
	memset(r, 0, sizeof(*r));
	r->kind = kind;
	r->nframes = 1;
	r->text[r->len++] = letter;
	return ORFA_OK;
}

int orfa_req_version(orfa_req_t *r)
{
	int rc = command(r, ORFA_REQ_VERSION, 'V');

	if (rc == ORFA_OK) {
		put_end(r);
	}
	return rc;
}

int orfa_req_clear(orfa_req_t *r)
{
	int rc = command(r, ORFA_REQ_CLEAR, 'X');

	if (rc == ORFA_OK) {
		put_end(r);
	}
	return rc;
}

int orfa_req_local(orfa_req_t *r, int addr)
{
	/* L00 and L01 are the gateway's ERROR 04 */
	if (addr > 0xFF || (addr >= 0 && addr < 2)) {
		return ORFA_E_ARG;
	}
	if (command(r, ORFA_REQ_LOCAL, 'L') != ORFA_OK) {
		return ORFA_E_ARG;
	}
	if (addr >= 0) {
		put_byte(r, (uint8_t)addr);
	}
	put_end(r);
	return ORFA_OK;
}

int orfa_req_clock(orfa_req_t *r, long khz)
{
	/* C0000 is the gateway's ERROR 04 */
	if (khz > 0xFFFF || khz == 0) {
		return ORFA_E_ARG;
	}
	if (command(r, ORFA_REQ_CLOCK, 'C') != ORFA_OK) {
		return ORFA_E_ARG;
	}
	if (khz > 0) {
		put_byte(r, (uint8_t)(khz >> 8));
		put_byte(r, (uint8_t)khz);
	}
	put_end(r);
	return ORFA_OK;
}

/* --- replies -------------------------------------------------------------- */

static int hexval(char c)
{
	if (c >= '0' && c <= '9') {
		return c - '0';
	}
	if (c >= 'A' && c <= 'F') {
		return c - 'A' + 10;
	}
	if (c >= 'a' && c <= 'f') {
		return c - 'a' + 10;
	}
	return -1;
}

/* `n` bytes from 2n hex digits at `s`; 0 or ORFA_E_PROTOCOL. */
static int unhex(const char *s, size_t n, uint8_t *out)
{
	size_t i;

	for (i = 0; i < n; i++) {
		int hi = hexval(s[2 * i]);
		int lo = hexval(s[2 * i + 1]);

		if (hi < 0 || lo < 0) {
			return ORFA_E_PROTOCOL;
		}
		out[i] = (uint8_t)(hi << 4 | lo);
	}
	return ORFA_OK;
}

static void result(orfa_reply_t *o, orfa_reply_type_t type, uint8_t address, size_t size)
{
	memset(o, 0, sizeof(*o));
	o->type = type;
	o->address = address;
	o->size = size;
	o->last = 1;
}

static int parse_i2c(const orfa_req_t *r, const char *line, size_t len, orfa_reply_t *out)
{
	size_t pos = 0;
	size_t i, k;

	for (i = 0; i < r->nframes; i++) {
		const orfa_frame_t *f = &r->frames[i];
		size_t n = f->count;

		if (pos + 2 > len || line[pos] != 'S') {
			return ORFA_E_PROTOCOL;
		}
		if (f->address & 1) {
			if (line[pos + 1] != 'R' || pos + 2 + 2 * n > len) {
				return ORFA_E_PROTOCOL;
			}
			result(&out[i], ORFA_REPLY_READ, f->address, n);
			if (unhex(line + pos + 2, n, out[i].data) != ORFA_OK) {
				return ORFA_E_PROTOCOL;
			}
			pos += 2 + 2 * n;
		} else {
			if (line[pos + 1] != 'W' || pos + 2 + n > len) {
				return ORFA_E_PROTOCOL;
			}
			for (k = 0; k < n; k++) {
				if (line[pos + 2 + k] != 'A') {
					return ORFA_E_PROTOCOL;
				}
			}
			result(&out[i], ORFA_REPLY_WRITE, f->address, n);
			pos += 2 + n;
		}
		out[i].frame = (uint8_t)i;
		out[i].last = i + 1 == r->nframes;
	}
	if (pos + 1 != len || line[pos] != 'P') {
		return ORFA_E_PROTOCOL;
	}
	return (int)r->nframes;
}

int orfa_reply_parse(const orfa_req_t *r, const char *line, size_t len,
		     orfa_reply_t *out, int *code)
{
	if (r == NULL || line == NULL || out == NULL || !r->ended) {
		return ORFA_E_ARG;
	}
	if (len > ORFA_REPLY_MAX) {
		return ORFA_E_PROTOCOL;
	}
	if (len == 8 && memcmp(line, "ERROR ", 6) == 0) {
		uint8_t c;

		if (unhex(line + 6, 1, &c) != ORFA_OK) {
			return ORFA_E_PROTOCOL;
		}
		if (code != NULL) {
			*code = c;
		}
		return ORFA_E_REPLY;
	}
	switch (r->kind) {
	case ORFA_REQ_I2C:
		return parse_i2c(r, line, len, out);
	case ORFA_REQ_VERSION:
		if (len < 2 || line[0] != 'V') {
			return ORFA_E_PROTOCOL;
		}
		result(out, ORFA_REPLY_VERSION, 0, len - 1);
		memcpy(out->data, line + 1, len - 1);
		return 1;
	case ORFA_REQ_CLEAR:
		if (len != 1 || line[0] != 'X') {
			return ORFA_E_PROTOCOL;
		}
		result(out, ORFA_REPLY_CLEAR, 0, 0);
		return 1;
	case ORFA_REQ_LOCAL:
		if (len != 3 || line[0] != 'L') {
			return ORFA_E_PROTOCOL;
		}
		result(out, ORFA_REPLY_LOCAL, 0, 1);
		return unhex(line + 1, 1, out->data) == ORFA_OK ? 1 : ORFA_E_PROTOCOL;
	case ORFA_REQ_CLOCK:
		if (len != 5 || line[0] != 'C') {
			return ORFA_E_PROTOCOL;
		}
		result(out, ORFA_REPLY_CLOCK, 0, 2);
		return unhex(line + 1, 2, out->data) == ORFA_OK ? 1 : ORFA_E_PROTOCOL;
	}
	return ORFA_E_ARG;
}

const char *orfa_strerror(int err)
{
	switch (err) {
	case ORFA_OK:
		return "success";
	case ORFA_E_ARG:
		return "invalid argument";
	case ORFA_E_LIMIT:
		return "request over 128 characters or its reply over 127";
	case ORFA_E_IO:
		return "serial port error";
	case ORFA_E_TIMEOUT:
		return "no reply in time";
	case ORFA_E_PROTOCOL:
		return "reply does not answer the request";
	case ORFA_E_REPLY:
		return "the gateway answered ERROR";
	case ORFA_E_STATE:
		return "call out of order";
	case ORFA_E_FULL:
		return "too many requests whose results were not read";
	}
	return "unknown error";
}

const char *orfa_code_str(int code)
{
	/* the firmware's list of the codes and their meanings */
	switch (code) {
#define ORFA_CODE_CASE(name, value, text) case value: return text;
	SG_ERR_LIST(ORFA_CODE_CASE)
#undef ORFA_CODE_CASE
	}
	return "unknown protocol error";
}
