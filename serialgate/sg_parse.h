/*
 * The serial gateway's request parser (docs/protocol.md).
 *
 * Pure: no hardware, so it also compiles and is tested on the host. It takes
 * one character at a time as the UART delivers it, so that when a line's
 * terminator arrives only the execution of the request is left.
 */
#ifndef SG_PARSE_H
#define SG_PARSE_H

#include <stdbool.h>
#include <stdint.h>

/* The protocol's error codes (docs/protocol.md): X(name, code, when). The
 * host's board map (tools/mapgen.c) takes names and meanings from here. */
#define SG_ERR_LIST(X) \
	X(INTERNAL, 0x01, "internal parser error") \
	X(COMMAND, 0x02, "unknown command letter") \
	X(HEX, 0x03, "not a hex digit where a byte is expected, or a byte with one digit") \
	X(DATA, 0x04, "wrong data, a request or reply over its limit, or characters lost") \
	X(NO_P, 0x05, "the line ended before the P of an I2C request") \
	X(ADDR_NACK, 0x06, "no ACK for an address byte (no device, bus not to be had, register not readable)") \
	X(DATA_NACK, 0x07, "no ACK for a data byte (or a local write a driver rejects)")

typedef enum {
	SG_OK = 0x00,
#define SG_ERR_ENUM(name, code, text) SG_ERR_##name = code,
	SG_ERR_LIST(SG_ERR_ENUM)
#undef SG_ERR_ENUM
} sg_err_t;

#define SG_LINE_MAX   128  /* characters of a request before its terminator */
#define SG_REPLY_MAX  127  /* characters of a reply before CR LF */
/* Parsed request: I2C frames as [addr][n][n bytes], a read frame's n bytes
 * being room for the data it will read. Written bytes take 2 characters each
 * and read bytes 2 reply characters each, so the limits bound this. */
#define SG_BUF_SIZE   128

/* What the receive ring (serialgate/sg_rx.h) writes where it lost
 * characters: SG_CHAR_LOST then two bytes (low, high) = the requests whose
 * ends were lost, the line going on being gone; SG_CHAR_END_LOST in place of
 * the end of a request that lost characters; SG_CHAR_END_EMPTY in place of
 * the end of an empty or comment line that lost characters. */
#define SG_CHAR_LOST      0x80
#define SG_CHAR_END_LOST  0x81
#define SG_CHAR_END_EMPTY 0x82

typedef enum {
	SG_CMD_NONE = 0,
	SG_CMD_VERSION,
	SG_CMD_CLEAR,
	SG_CMD_LOCAL,    /* args: 0 bytes (read) or 1 (set) */
	SG_CMD_CLOCK,    /* args: 0 bytes (read) or 2 (set, kHz big-endian) */
	SG_CMD_I2C,
} sg_cmd_t;

/* What the parser says after each character. */
typedef enum {
	SG_MORE = 0,     /* the line goes on */
	SG_IGNORED,      /* an empty line or a comment ended: no reply */
	SG_REQUEST,      /* a request ended: execute it, or reply its error */
	SG_LOST,         /* `lost` requests were lost whole or in part: reply
			  * ERROR 04 to each */
} sg_event_t;

typedef struct {
	uint8_t state;
	uint8_t err;        /* first error of the line, SG_OK if none */
	uint8_t cmd;        /* sg_cmd_t */
	uint8_t len;        /* characters of the line so far */
	uint8_t hi;         /* first digit of a byte in progress, 0xFF if none */
	uint8_t nbytes;     /* bytes used in buf */
	uint8_t frame;      /* index in buf of the current frame's [addr] */
	uint8_t reply_len;  /* length of the reply this request will have */
	uint16_t lost;      /* after SG_LOST: how many ERROR 04 to reply */
	uint8_t lost_info;  /* bytes of a lost-run record still to come */
	uint8_t buf[SG_BUF_SIZE];
} sg_parser_t;

void sg_parse_init(sg_parser_t *p);

/* The parser's states (`state`; sg_parse.c's, here for sg_parse_char()). */
enum {
	SG_ST_BEGIN,    /* first character of a line */
	SG_ST_LEAD,     /* only spaces so far */
	SG_ST_COMMENT,  /* a '#' line */
	SG_ST_ARGS,     /* L / C: optional bytes */
	SG_ST_ADDR,     /* I2C: a frame's address byte expected */
	SG_ST_WDATA,    /* I2C write frame: data bytes, S or P */
	SG_ST_RCOUNT,   /* I2C read frame: the count byte expected */
	SG_ST_RDONE,    /* I2C read frame complete: S or P */
	SG_ST_DONE,     /* complete command: only spaces may follow */
	SG_ST_ERROR,    /* discard the rest of the line */
};

#define SG_NO_DIGIT 0xFF  /* `hi` between bytes; sg_hex_value() of a non-digit */

static inline uint8_t sg_hex_value(uint8_t c)
{
	if ((uint8_t)(c - '0') <= 9) {
		return (uint8_t)(c - '0');
	}
	c = (uint8_t)((c | 0x20) - 'a');  /* lower case */
	return c <= 5 ? (uint8_t)(c + 10) : SG_NO_DIGIT;
}

/* A digit (0 to 15) as a byte's high nibble: written as the rotate it
 * equals for such a value, which avr-gcc makes one SWAP (its shift by 4
 * became a MUL and a move, ~5 cycles more on every byte of a request). */
static inline uint8_t sg_nibble_up(uint8_t d)
{
	return (uint8_t)(d << 4 | d >> 4);
}

/* Feeds one character. After SG_REQUEST, `err` holds the error to reply (or
 * SG_OK), `cmd`, `nbytes` and `buf` the request; the parser is ready for the
 * next line. */
sg_event_t sg_parse_char(sg_parser_t *p, uint8_t c);

/* A byte complete in a state that takes one (SG_ST_ARGS to SG_ST_RCOUNT). */
sg_event_t sg_parse_byte(sg_parser_t *p, uint8_t b);

/* An I2C frame begins (its S). */
sg_event_t sg_parse_frame(sg_parser_t *p);

/* The states sg_parse_run() takes characters in (a command's arguments, an
 * I2C request's frames, a complete command's trailing spaces). */
static inline bool sg_parse_in_run(const sg_parser_t *p)
{
	return (uint8_t)(p->state - SG_ST_ARGS) <= SG_ST_DONE - SG_ST_ARGS;
}

/* Feeds the run of characters at ring[tail], ring[tail + 1], ... (indices
 * wrapping at 256) up to *head that keep the parser in a request's common
 * path: an I2C request's first S, a space between bytes, a byte's digits,
 * a frame's S or P after a byte, the line short; each of them SG_MORE.
 * *head is read again when all that had come is taken (the receive
 * interrupt moves it: what came meanwhile is taken in the same call); the
 * run stops at the ring's end, the next goes on from ring[0]. Returns the
 * index of the first character it did not take (*head if it took all):
 * that one is for sg_parse_char(). In one loop with the line's length and the digit in
 * progress in registers, a write frame's data byte and a frame's address
 * stored in place: ~40 cycles a character, where at 460800 baud a
 * character lasts 160 (docs/protocol.md, The line); sg_parse_char()'s
 * whole rule does the same with them (tests/unit's test_parse_run). */
uint8_t sg_parse_run(sg_parser_t *p, const uint8_t *ring, uint8_t tail, const volatile uint8_t *head);

#endif
