/*
 * The manual's chapter 5 example, orfa_get_drivers, as a program: the driver
 * list of an ORFA board by introspection, through a gateway on a serial port.
 *
 *     examples/get_drivers PORT [ADDRESS]
 *
 * ADDRESS is the board's address in the protocol's 8-bit form, in hex (10 or
 * 0x10); the default AA is the gateway's own. The port runs at 115200 baud,
 * or at $ORFA_BAUD (a gateway built with BAUD=14400, say). One line per driver:
 *
 *     UID 0x0020  version 1.1  registers 0x02-0x09 (8)
 *
 * Exit status 0, or 1 with one line on stderr (a port that does not open, an
 * ERROR reply, no reply, a device whose answers are not an ORFA driver list),
 * 2 for wrong arguments.
 *
 * Not every device that answers is an ORFA board (an EEPROM answers the same
 * reads with whatever it holds), so the list is checked before anything is
 * printed: driver 1 is introspection (UID 0x0000, registers 0x00-0x01), every
 * next driver's registers start where the previous one's end, none runs past
 * 0xFF and no other driver has introspection's UID.
 *
 * Kept from the manual: MAX_PER_PKG = 10 records per read (6 bytes each: ten
 * fill the 127-character reply exactly, "SWAASR" + 120 hex digits + "P"),
 * all reads committed before any reply is read (pipelining), then the
 * replies taken one frame result at a time. Fixed from the manual:
 *  - it always sent a last read of `count % MAX_PER_PKG` records, a read of
 *    0 bytes (ERROR 04) when count is a multiple of 10; here that read is
 *    only sent when some records are left;
 *  - `reply_cnt = max_cnt*2 + (min_cnt)? 2:0` parses as
 *    `(max_cnt*2 + min_cnt) ? 2 : 0`; here the count of results is computed
 *    from the requests actually sent;
 *  - `if (reply->type == OR_READ) continue;` skipped the very replies it
 *    wanted; here write results are skipped and read results decoded, and
 *    the record loop is inside the reply loop (the manual closed the loop
 *    before it);
 *  - a count of 0 (impossible: introspection counts itself) is reported
 *    instead of read on, and every call's return code is checked.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "orfa.h"

/* introspection register always zero */
#define INTRO 0x00

/* Calculated for the 127-character reply: one record is 6 bytes (12 hex
 * digits); a reply is "SW" + 2 A's + "SR" + the data + "P", 7 characters. */
#define MAX_PER_PKG 10
#define PKG_LEN 6

#define LOCAL_ADDRESS 0xAA

static const char *prog = "get_drivers";

static int fail(const char *port, unsigned address, orfa_t *o, int rc)
{
	if (rc == ORFA_E_REPLY) {
		int code = orfa_reply_code(o);

		fprintf(stderr, "%s: %s: address 0x%02X: ERROR %02X (%s)\n", prog, port, address,
			code, orfa_code_str(code));
	} else if (rc == ORFA_E_IO) {
		fprintf(stderr, "%s: %s: %s\n", prog, port, strerror(errno));
	} else {
		fprintf(stderr, "%s: %s: address 0x%02X: %s\n", prog, port, address,
			orfa_strerror(rc));
	}
	orfa_close(o);
	return 1;
}

/* One transaction: select introspection entry `first`, read `count` bytes. */
static int ask(orfa_t *o, unsigned address, uint8_t first, size_t count)
{
	uint8_t buf[2] = {INTRO, first};
	int rc = orfa_tr_start(o);

	if (rc == ORFA_OK) {
		rc = orfa_write(o, (uint8_t)address, buf, 2);
	}
	if (rc == ORFA_OK) {
		rc = orfa_read(o, (uint8_t)address, count);
	}
	if (rc == ORFA_OK) {
		rc = orfa_tr_commit(o);
	}
	return rc;
}

/* The read result of a write+read transaction; the write's is skipped. */
static int read_result(orfa_t *o, orfa_reply_t *reply)
{
	int rc = orfa_read_reply(o, reply);             /* SW */

	if (rc == ORFA_OK && reply->type != ORFA_REPLY_WRITE) {
		return ORFA_E_PROTOCOL;
	}
	if (rc == ORFA_OK) {
		rc = orfa_read_reply(o, reply);         /* SR */
	}
	if (rc == ORFA_OK && reply->type != ORFA_REPLY_READ) {
		return ORFA_E_PROTOCOL;
	}
	return rc;
}

/* Why `count` records are no ORFA driver list, in `why`; 0 if they are one. */
static int implausible(const uint8_t *recs, unsigned count, char *why, size_t size)
{
	unsigned next = 0;              /* where the next driver's registers start */
	unsigned i;

	for (i = 0; i < count; i++) {
		const uint8_t *d = recs + (size_t)i * PKG_LEN;
		unsigned uid = (unsigned)d[0] << 8 | d[1];
		unsigned start = d[4];
		unsigned n = d[5];

		if (i == 0 && (uid != 0x0000 || start != 0x00 || n != 2)) {
			snprintf(why, size, "driver 1 is UID 0x%04X with registers from 0x%02X (%u), "
				 "not introspection (UID 0x0000, registers 0x00-0x01)", uid, start, n);
			return 1;
		}
		if (i > 0 && uid == 0x0000) {
			snprintf(why, size, "driver %u has UID 0x0000, introspection's", i + 1);
			return 1;
		}
		if (start != next) {
			snprintf(why, size, "driver %u's registers start at 0x%02X, not at 0x%02X "
				 "where driver %u's end", i + 1, start, next, i);
			return 1;
		}
		if (start + n > 0x100) {
			snprintf(why, size, "driver %u's registers run past 0xFF (0x%02X-0x%03X)",
				 i + 1, start, start + n - 1);
			return 1;
		}
		next = start + n;
	}
	return 0;
}

static void print_record(const uint8_t *d)
{
	unsigned uid = (unsigned)d[0] << 8 | d[1];
	unsigned start = d[4];
	unsigned count = d[5];

	printf("UID 0x%04X  version %u.%u  registers ", uid, d[2], d[3]);
	if (count == 0) {
		printf("none (0)\n");
	} else {
		printf("0x%02X-0x%02X (%u)\n", start, start + count - 1, count);
	}
}

int main(int argc, char **argv)
{
	const char *port;
	unsigned long address = LOCAL_ADDRESS;
	long baud;
	orfa_t *o = NULL;
	orfa_reply_t reply;
	unsigned count, max_cnt, min_cnt, requests, i;
	static uint8_t recs[255 * PKG_LEN];      /* the count is one byte */
	size_t got = 0;
	char why[160];
	int rc;

	if (argc < 2 || argc > 3 || argv[1][0] == '\0') {
		fprintf(stderr, "usage: %s PORT [ADDRESS]  (ADDRESS: 8-bit hex, default AA)\n", prog);
		return 2;
	}
	port = argv[1];
	if (argc == 3) {
		char *end;

		errno = 0;
		address = strtoul(argv[2], &end, 16);
		if (errno != 0 || end == argv[2] || *end != '\0' || argv[2][0] == '-' ||
		    address > 0xFF || (address & 1)) {
			fprintf(stderr, "%s: bad address '%s': give the 8-bit write address in hex, "
				"00-FE and even (10 or 0x10)\n", prog, argv[2]);
			return 2;
		}
	}
	baud = 115200;
	if (getenv("ORFA_BAUD") != NULL && getenv("ORFA_BAUD")[0] != '\0') {
		const char *text = getenv("ORFA_BAUD");
		char *end;

		errno = 0;
		baud = strtol(text, &end, 10);
		if (errno != 0 || end == text || *end != '\0' || baud <= 0) {
			fprintf(stderr, "%s: bad ORFA_BAUD '%s': the gateway's rate in bits per "
				"second (115200)\n", prog, text);
			return 2;
		}
	}
	rc = orfa_open(&o, port, baud);
	if (rc != ORFA_OK) {
		return fail(port, (unsigned)address, NULL, rc);
	}

	/* get drivers count */
	rc = ask(o, (unsigned)address, 0, 1);
	if (rc == ORFA_OK) {
		rc = read_result(o, &reply);
	}
	if (rc == ORFA_OK && reply.size != 1) {
		rc = ORFA_E_PROTOCOL;
	}
	if (rc != ORFA_OK) {
		return fail(port, (unsigned)address, o, rc);
	}
	count = reply.data[0];
	if (count == 0) {
		fprintf(stderr, "%s: %s: address 0x%02lX: introspection counts 0 drivers\n", prog,
			port, address);
		orfa_close(o);
		return 1;
	}

	max_cnt = count / MAX_PER_PKG;
	min_cnt = count % MAX_PER_PKG;

	/* every read first, the replies after (the library waits for replies
	 * itself should the requests outrun the gateway's receive buffer) */
	for (i = 0; i < max_cnt && rc == ORFA_OK; i++) {
		rc = ask(o, (unsigned)address, (uint8_t)(MAX_PER_PKG * i + 1), MAX_PER_PKG * PKG_LEN);
	}
	if (min_cnt != 0 && rc == ORFA_OK) {
		rc = ask(o, (unsigned)address, (uint8_t)(MAX_PER_PKG * max_cnt + 1), min_cnt * PKG_LEN);
	}
	requests = max_cnt + (min_cnt != 0 ? 1 : 0);

	for (i = 0; i < requests && rc == ORFA_OK; i++) {
		rc = read_result(o, &reply);
		if (rc != ORFA_OK) {
			break;
		}
		if (reply.size % PKG_LEN || got + reply.size > (size_t)count * PKG_LEN) {
			fprintf(stderr, "%s: %s: wrong read reply size: %zu\n", prog, port, reply.size);
			orfa_close(o);
			return 1;
		}
		memcpy(recs + got, reply.data, reply.size);
		got += reply.size;
	}
	if (rc != ORFA_OK) {
		return fail(port, (unsigned)address, o, rc);
	}
	orfa_close(o);
	if (implausible(recs, count, why, sizeof(why))) {
		fprintf(stderr, "%s: %s: address 0x%02lX: not an ORFA board: %s\n", prog, port,
			address, why);
		return 1;
	}
	for (i = 0; i < count; i++) {
		print_record(recs + (size_t)i * PKG_LEN);
	}
	return 0;
}
