/*
 * ORFA host C library: the calls of the manual's chapter 5 on a serial port
 * to an ORFA gateway (POSIX termios, and Linux's termios2 for the rates up to
 * 4000000 that termios has no name for: orfa_speed.h). docs/c-library.md
 * has the whole story; in short:
 *
 *     orfa_t *o;
 *     orfa_reply_t r;
 *     uint8_t buf[2] = {0x00, 0x00};
 *
 *     if (orfa_open(&o, "/dev/ttyUSB0", 115200) != ORFA_OK) ... (errno tells)
 *     orfa_tr_start(o);
 *     orfa_write(o, 0xAA, buf, 2);           S AA 00 00
 *     orfa_read(o, 0xAA, 1);                 S AB 01
 *     orfa_tr_commit(o);                     P, sent
 *     orfa_read_reply(o, &r);                the SW result: ORFA_REPLY_WRITE
 *     orfa_read_reply(o, &r);                the SR result: r.data[0] = count
 *     orfa_close(o);
 *
 * The manual's calls have no handle; here each takes the connection first.
 * Every call returns ORFA_OK (0) or a negative ORFA_E_* code (orfa_line.h).
 */
#ifndef ORFA_H
#define ORFA_H

#include "orfa_line.h"

/* A connection to one gateway: its port, the transaction being built and
 * the requests sent whose results were not all read yet. */
typedef struct orfa orfa_t;

/* Requests sent but not yet answered, at most (their results are kept until
 * read). */
#define ORFA_QUEUE_MAX 32
/* Milliseconds orfa_read_reply waits for a reply line, unless changed. */
#define ORFA_TIMEOUT_MS 2000

/* Opens `path` raw 8N1 at `baud` (the rates termios names by name, others up
 * to 4000000 by number: orfa_speed.h) and drops what was waiting in it; then
 * brings the line in step: an LF ends whatever partial line the board holds,
 * `V` and `L` follow, and every line up to their replies is dropped, so the
 * first request is answered as itself. ORFA_E_ARG for a rate it cannot set,
 * ORFA_E_IO with errno set when the port does not open, ORFA_E_TIMEOUT
 * (errno ETIMEDOUT) when no gateway answers within ORFA_TIMEOUT_MS in all,
 * whatever else the line carries. */
int orfa_open(orfa_t **o, const char *path, long baud);

/* Closes the port (its settings put back) and frees `o`; NULL is allowed. */
void orfa_close(orfa_t *o);

/* How long orfa_read_reply (and a commit that must wait for room) waits for
 * one reply line, in milliseconds (> 0). */
int orfa_set_timeout(orfa_t *o, int ms);

/* A new I2C transaction; one that was started and not committed is dropped. */
int orfa_tr_start(orfa_t *o);

/* A write frame: `address` in the protocol's 8-bit form (bit 0 ignored),
 * then `len` bytes (0: an address probe). */
int orfa_write(orfa_t *o, uint8_t address, const uint8_t *buf, size_t len);

/* A read frame of `count` bytes (1..) from `address` (8-bit form; bit 0 is
 * set for the read). */
int orfa_read(orfa_t *o, uint8_t address, size_t count);

/* Sends the transaction as one S..S..P line. Refused (nothing sent) when a
 * frame was refused (its error again) or the transaction is empty
 * (ORFA_E_ARG). Requests may be committed back to back without reading their
 * results (pipelining): when the requests in flight would overflow the
 * gateway's receive buffer (the flow rule of docs/protocol.md) the commit first waits for
 * replies, keeping them for orfa_read_reply. */
int orfa_tr_commit(orfa_t *o);

/* The one-line commands, sent like a commit; each gives one result:
 * V (ORFA_REPLY_VERSION), X (ORFA_REPLY_CLEAR), L (addr < 0 reads the local
 * address, ORFA_REPLY_LOCAL), C (khz < 0 reads the clock, ORFA_REPLY_CLOCK). */
int orfa_version(orfa_t *o);
int orfa_clear(orfa_t *o);
int orfa_local(orfa_t *o, int addr);
int orfa_clock(orfa_t *o, long khz);

/* The next result, in commit order, one frame at a time: a commit of a
 * write and a read gives the write's result (ORFA_REPLY_WRITE), then the
 * read's (ORFA_REPLY_READ, its bytes in data). An `ERROR xx` reply answers
 * the whole request: ORFA_E_REPLY once (orfa_reply_code gives xx), and the
 * request's other results are gone (the gateway makes no partial reply).
 * ORFA_E_PROTOCOL likewise for a reply line that does not fit the request.
 * ORFA_E_TIMEOUT leaves the request waiting (a later call waits again).
 * ORFA_E_STATE when no result is expected. */
int orfa_read_reply(orfa_t *o, orfa_reply_t *reply);

/* The protocol code (1..7) of the last ORFA_E_REPLY, 0 before any. */
int orfa_reply_code(const orfa_t *o);

/* Results still expected: of requests committed and of the one being read. */
int orfa_pending(const orfa_t *o);

#endif
