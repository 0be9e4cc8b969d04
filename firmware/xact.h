/*
 * xact: register transactions one byte at a time (docs/registers.md, "Frames"), shared by
 * both front ends. The serial gateway's local path and the TWI slave call the
 * same five events, in the shape of Zephyr's I2C target callbacks:
 *
 *   xact_write_requested  a write frame begins (own address + W acknowledged)
 *   xact_write_received   one byte of it: the register byte, then data
 *   xact_read_requested   a read frame begins (own address + R acknowledged)
 *   xact_read_processed   the next byte the master reads
 *   xact_frame_end        repeated START or STOP: a write frame's data are
 *                         delivered to the driver now, all or nothing
 *
 * The front end owns the bytes: it hands in the buffer a frame's data go to
 * (a write's data wait there until the frame ends; a read's driver answers
 * are put there). A driver is asked for read data only when the bytes it gave
 * last are used up, so a read never moves a driver's cursor (introspection)
 * further than the bytes the master really takes, give or take the rest of
 * one answer.
 *
 * Pure register logic over regmap.h: compiled and fuzzed on the host too.
 */
#ifndef ORFA_XACT_H
#define ORFA_XACT_H

#include <stdbool.h>
#include <stdint.h>

#include "firmware/regmap.h"

/* Forget any frame in progress (reset). */
void xact_init(void);

/* The master abandoned the frame in progress (a bus error, a frame gone
 * quiet: twi_quiet.h): nothing of it is applied, and a write that held
 * data sets the status to REG_DROPPED (one refused already keeps its
 * reason; a bare register selection stands). */
void xact_frame_drop(void);

/* A write frame begins; its data may use `cap` bytes at `buf`. */
void xact_write_requested(uint8_t *buf, uint8_t cap);

/* One byte of the write frame. False: refused (a register byte no driver
 * maps, data beyond `cap`, data for the status register); the frame then
 * changes nothing and later bytes are refused too. The status register
 * tells why. */
bool xact_write_received(uint8_t byte);

/* The write frame's first byte, its register, as xact_write_received()
 * takes it (the frame has just begun). */
bool xact_write_select(uint8_t reg);

/* The next n data bytes of the write frame at once, already in place in its
 * buffer: exactly as n calls of xact_write_received() with them would
 * take them (a front end that handed in the very bytes it parsed: the
 * gateway; tests/unit/test_xact.c compares the two) when they fit the
 * buffer. n bytes that do not fit are refused whole as too long
 * (REG_BAD_LENGTH) before any is checked, where the bytes one at a time
 * would have their check first; the gateway's buffer is its frame, so it
 * never gives more. False: refused, as there. */
bool xact_write_taken(uint8_t n);

/* A read frame begins; driver answers go to `cap` (>= 1) bytes at `buf` (at
 * least REGMAP_READ_MAX for a front end that does not know the read length).
 * False when the selected register cannot be read (status tells). */
bool xact_read_requested(uint8_t *buf, uint8_t cap);

/* The next byte of the read frame. False, and *byte = 0xFF, when the
 * register gives nothing (cannot be read). */
bool xact_read_processed(uint8_t *byte);

/* The next n bytes of the read frame at once, exactly as n calls of
 * xact_read_processed() would take them (a driver is asked as often, at the
 * same bytes), left where they are in the buffer: for a front end that
 * knows its read length and handed in the very bytes it replies from (the
 * gateway). False when the register gives nothing. */
bool xact_read_take(uint8_t n);

/* True when a write frame holds data that xact_frame_end() will deliver to
 * a driver (a front end that must not call drivers from an interrupt defers
 * that frame end). */
bool xact_write_pending(void);

/* True when xact_read_processed() can answer from the buffer, without asking
 * a driver. */
bool xact_read_buffered(void);

/* The frame ends (repeated START or STOP). A write frame with data is
 * delivered to its driver now: returns REG_OK, or why it was rejected (also
 * for a frame refused byte by byte). Read frames and register selections
 * return REG_OK. */
reg_status_t xact_frame_end(void);

#endif
