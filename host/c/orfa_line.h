/*
 * ORFA host C library, the pure part: request lines built frame by frame and
 * reply lines parsed into one result per frame (docs/protocol.md). No I/O,
 * so it is unit-tested without a port (tests/unit/test_orfa_line.c);
 * orfa.h puts it on a serial port.
 */
#ifndef ORFA_LINE_H
#define ORFA_LINE_H

#include <stddef.h>
#include <stdint.h>

/* The protocol's limits (docs/protocol.md, "Limits"): characters of a request before its
 * terminator, of a reply before CR LF. orfa_line.c checks them against the
 * firmware's own definitions. */
#define ORFA_REQUEST_MAX 128
#define ORFA_REPLY_MAX   127
/* The most frames one request can hold: an address-only write frame ("SAA")
 * is the shortest, three characters, and the line ends with "P". */
#define ORFA_FRAMES_MAX  ((ORFA_REQUEST_MAX - 1) / 3)
/* The most data bytes one result carries (a V reply's text is the longest). */
#define ORFA_DATA_MAX    (ORFA_REPLY_MAX - 1)

/* Return codes: 0 is success, errors are negative. */
enum {
	ORFA_OK = 0,
	ORFA_E_ARG = -1,       /* a bad argument: read count 0, nothing to commit, NULL */
	ORFA_E_LIMIT = -2,     /* the request would be over 128 characters or its
				* reply over 127: refused, nothing sent */
	ORFA_E_IO = -3,        /* the port failed (errno tells) */
	ORFA_E_TIMEOUT = -4,   /* no reply line in time */
	ORFA_E_PROTOCOL = -5,  /* a reply line that does not answer the request */
	ORFA_E_REPLY = -6,     /* the gateway answered ERROR xx (orfa_reply_code) */
	ORFA_E_STATE = -7,     /* a call out of order (orfa_write before orfa_tr_start,
				* orfa_read_reply with nothing committed) */
	ORFA_E_FULL = -8,      /* too many requests whose results were not read */
};

typedef enum {
	ORFA_REQ_I2C = 0,      /* S..S..P */
	ORFA_REQ_VERSION,      /* V */
	ORFA_REQ_CLEAR,        /* X */
	ORFA_REQ_LOCAL,        /* L, L<addr> */
	ORFA_REQ_CLOCK,        /* C, C<kHz> */
} orfa_req_kind_t;

typedef enum {
	ORFA_REPLY_WRITE = 1,  /* SW A..: size = bytes written (acknowledged) */
	ORFA_REPLY_READ,       /* SR ..: size = bytes read, in data */
	ORFA_REPLY_VERSION,    /* V1.1: size = characters of the version, in data */
	ORFA_REPLY_CLEAR,      /* X: size 0 */
	ORFA_REPLY_LOCAL,      /* LAA: size 1, the local address */
	ORFA_REPLY_CLOCK,      /* C0063: size 2, the clock in kHz, big-endian */
} orfa_reply_type_t;

/* One frame of a request: its address byte as sent (bit 0 set: a read) and
 * the bytes written or asked for. */
typedef struct {
	uint8_t address;
	uint8_t count;
} orfa_frame_t;

/* A request line in the making, and what its reply must hold. */
typedef struct {
	orfa_req_kind_t kind;
	int error;                  /* a refused frame: the whole request is refused */
	int ended;                  /* terminator written */
	char text[ORFA_REQUEST_MAX + 2];   /* + "\n" + NUL */
	size_t len;                 /* characters in text */
	size_t reply_len;           /* characters its reply will have (I2C) */
	orfa_frame_t frames[ORFA_FRAMES_MAX];
	size_t nframes;
} orfa_req_t;

/* One result: a frame's of an I2C request, or a V/X/L/C reply's. */
typedef struct {
	orfa_reply_type_t type;
	uint8_t address;            /* the frame's address byte as sent; 0 for V/X/L/C */
	uint8_t frame;              /* its index in the request */
	uint8_t last;               /* 1 on the request's last result */
	size_t size;
	uint8_t data[ORFA_DATA_MAX];
} orfa_reply_t;

/* An I2C request with no frames yet. */
void orfa_req_start(orfa_req_t *r);

/* Appends a write frame: `address` in the protocol's 8-bit form (bit 0 is
 * ignored: cleared), then `len` bytes. ORFA_E_LIMIT when the request or its
 * reply would break a limit; the request is then refused as a whole. */
int orfa_req_write(orfa_req_t *r, uint8_t address, const uint8_t *buf, size_t len);

/* Appends a read frame of `count` bytes (1..) from `address` (bit 0 is set).
 * ORFA_E_ARG for count 0, ORFA_E_LIMIT as for writes. */
int orfa_req_read(orfa_req_t *r, uint8_t address, size_t count);

/* Ends the request: "P\n" for an I2C request. ORFA_E_ARG if it holds no
 * frame; the error of a refused frame if there was one. */
int orfa_req_end(orfa_req_t *r);

/* The one-line commands, ended: V, X, L (addr < 0: read it) and C (khz < 0:
 * read it; else 1..0xFFFF). ORFA_E_ARG for a value out of range. */
int orfa_req_version(orfa_req_t *r);
int orfa_req_clear(orfa_req_t *r);
int orfa_req_local(orfa_req_t *r, int addr);
int orfa_req_clock(orfa_req_t *r, long khz);

/* The results of an ended request `r` in its reply `line` (`len` characters,
 * CR LF removed): fills out[0 .. results-1] and returns how many, or
 * ORFA_E_REPLY with the protocol's code in *code for "ERROR xx", or
 * ORFA_E_PROTOCOL for a line that does not answer `r`. `out` has room for
 * ORFA_FRAMES_MAX results. */
int orfa_reply_parse(const orfa_req_t *r, const char *line, size_t len,
		     orfa_reply_t *out, int *code);

/* One line of text for a return code, and for a protocol error code (1..7). */
const char *orfa_strerror(int err);
const char *orfa_code_str(int code);

#endif
