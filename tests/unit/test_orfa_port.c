/*
 * The C library on a port (host/c/orfa.c), against a pseudo-terminal whose
 * other end this test plays the gateway on: the exact bytes each call puts
 * on the line, results one frame at a time in commit order, ERROR replies,
 * timeouts, lines that are no reply, and the flow rule (commits wait for
 * replies rather than overflow the gateway's receive buffer).
 */
#define _XOPEN_SOURCE 600

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "orfa.h"
#include "orfa_speed.h"

#include "check.h"

static int master = -1;
static char slave_path[128];

static void open_pty(void)
{
	master = posix_openpt(O_RDWR | O_NOCTTY);
	if (master < 0 || grantpt(master) < 0 || unlockpt(master) < 0) {
		perror("posix_openpt");
		exit(2);
	}
	snprintf(slave_path, sizeof(slave_path), "%s", ptsname(master));
}

/* What the library sent: `lines` lines read from the master side (each poll
 * bounded by a second, only so that a failing library cannot hang the test),
 * the line count deciding when all has come. */
static size_t sent(char *buf, size_t size, int lines)
{
	size_t n = 0;
	struct pollfd pfd = {master, POLLIN, 0};

	while (lines > 0 && n + 1 < size && poll(&pfd, 1, 1000) > 0) {
		ssize_t got = read(master, buf + n, size - 1 - n);

		if (got <= 0) {
			break;
		}
		for (ssize_t i = 0; i < got; i++) {
			lines -= buf[n + (size_t)i] == '\n';
		}
		n += (size_t)got;
	}
	buf[n] = '\0';
	return n;
}

/* Whether the library sent nothing: the master side stays empty for 100 ms
 * (the library writes before its call returns, so its bytes would be
 * there); what came, if anything, is in buf. */
static size_t sent_nothing(char *buf, size_t size)
{
	struct pollfd pfd = {master, POLLIN, 0};
	ssize_t got = poll(&pfd, 1, 100) > 0 ? read(master, buf, size - 1) : 0;

	buf[got > 0 ? got : 0] = '\0';
	return got > 0 ? (size_t)got : 0;
}

static void answer(const char *text)
{
	size_t len = strlen(text);

	if (write(master, text, len) != (ssize_t)len) {
		perror("write");
		exit(2);
	}
}

static int intro(orfa_t *o, uint8_t addr, uint8_t first, size_t count)
{
	uint8_t buf[2] = {0x00, first};
	int rc = orfa_tr_start(o);

	if (rc == ORFA_OK) {
		rc = orfa_write(o, addr, buf, 2);
	}
	if (rc == ORFA_OK) {
		rc = orfa_read(o, addr, count);
	}
	if (rc == ORFA_OK) {
		rc = orfa_tr_commit(o);
	}
	return rc;
}

static void test_open(void)
{
	orfa_t *o = (orfa_t *)1;

	errno = 0;
	CHECK(orfa_open(&o, "/nonexistent/tty", 115200) == ORFA_E_IO && errno == ENOENT,
	      "missing port: errno %d", errno);
	CHECK(o == NULL, "no handle");
	CHECK(orfa_open(&o, slave_path, 0) == ORFA_E_ARG, "rate 0");
	CHECK(orfa_open(&o, slave_path, -9600) == ORFA_E_ARG, "a negative rate");
	CHECK(orfa_open(&o, slave_path, 4000001) == ORFA_E_ARG, "a rate above 4 Mbit/s");
	CHECK(orfa_open(NULL, slave_path, 115200) == ORFA_E_ARG, "no handle pointer");
	orfa_close(NULL);
}

/* The rates a gateway can be built for that termios has no name for go by
 * number (termios2 on Linux), and a named one after them goes back to a
 * name: the port's rate is what was asked, read on a descriptor of our own. */
static void test_rates_by_number(void)
{
	static const long rates[] = {14400, 28800, 76800, 115200};
	int fd = open(slave_path, O_RDWR | O_NOCTTY);
	size_t i;

	CHECK(fd >= 0, "open %s: %s", slave_path, strerror(errno));
	for (i = 0; i < sizeof(rates) / sizeof(rates[0]) && fd >= 0; i++) {
		orfa_t *o = NULL;
		int rc = orfa_open(&o, slave_path, rates[i]);

		CHECK(rc == ORFA_OK, "open at %ld: %d (%s)", rates[i], rc, strerror(errno));
		CHECK(orfa_speed_get(fd) == rates[i], "rate %ld: the port says %ld", rates[i],
		      orfa_speed_get(fd));
		orfa_close(o);
	}
	if (fd >= 0) {
		close(fd);
	}
}

static void test_exchange(orfa_t *o)
{
	orfa_reply_t r;
	char buf[1024];

	CHECK(orfa_read_reply(o, &r) == ORFA_E_STATE, "nothing committed");
	CHECK(orfa_tr_commit(o) == ORFA_E_STATE, "commit without start");
	CHECK(orfa_write(o, 0xAA, NULL, 0) == ORFA_E_STATE, "write without start");

	/* the manual's count request: raw line out, no CR added, no echo */
	CHECK(intro(o, 0xAA, 0, 1) == ORFA_OK, "commit");
	CHECK(orfa_pending(o) == 2, "pending %d", orfa_pending(o));
	sent(buf, sizeof(buf), 1);
	CHECK(strcmp(buf, "SAA0000SAB01P\n") == 0, "sent %s", buf);
	answer("SWAASR07P\r\n");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_WRITE && r.size == 2 &&
	      r.address == 0xAA, "SW");
	CHECK(orfa_pending(o) == 1, "pending %d", orfa_pending(o));
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_READ && r.size == 1 &&
	      r.data[0] == 7 && r.last, "SR");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_STATE, "all read");
	CHECK(orfa_pending(o) == 0, "pending %d", orfa_pending(o));

	/* pipelined: three commits, one line each, results in order; the
	 * replies arrive in one piece and in pieces */
	CHECK(intro(o, 0xAA, 1, 6) == ORFA_OK, "1");
	CHECK(orfa_version(o) == ORFA_OK, "V");
	CHECK(intro(o, 0x10, 0, 1) == ORFA_OK, "3");
	sent(buf, sizeof(buf), 3);
	CHECK(strcmp(buf, "SAA0001SAB06P\nV\nS100000S1101P\n") == 0, "sent %s", buf);
	CHECK(orfa_pending(o) == 5, "pending %d", orfa_pending(o));
	answer("SWAASR000001000002P\r\nV1.");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_WRITE, "1 SW");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_READ && r.size == 6 &&
	      r.data[5] == 2, "1 SR");
	answer("1\r\nSWAASR06P\r\n");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_VERSION && r.size == 3 &&
	      memcmp(r.data, "1.1", 3) == 0, "V");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.address == 0x10, "3 SW");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.address == 0x11 && r.data[0] == 6, "3 SR");

	/* ERROR answers the whole request: its other result is gone */
	CHECK(intro(o, 0x42, 0, 1) == ORFA_OK, "absent device");
	CHECK(orfa_version(o) == ORFA_OK, "V after it");
	sent(buf, sizeof(buf), 2);
	answer("ERROR 06\r\nV1.1\r\n");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_REPLY && orfa_reply_code(o) == 6, "ERROR 06");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_VERSION, "next request");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_STATE, "nothing left");

	/* refused frames: nothing goes out */
	CHECK(intro(o, 0xAA, 1, 61) == ORFA_E_LIMIT, "61 bytes");
	CHECK(orfa_tr_commit(o) == ORFA_E_LIMIT, "the commit is refused too");
	CHECK(orfa_tr_commit(o) == ORFA_E_STATE, "and the transaction is over");
	CHECK(orfa_tr_start(o) == ORFA_OK && orfa_read(o, 0xAA, 0) == ORFA_E_ARG &&
	      orfa_tr_commit(o) == ORFA_E_ARG, "read of 0");
	CHECK(orfa_tr_start(o) == ORFA_OK && orfa_tr_commit(o) == ORFA_E_ARG, "empty");
	CHECK(orfa_local(o, 0) == ORFA_E_ARG && orfa_clock(o, 0) == ORFA_E_ARG, "L00, C0000");
	CHECK(sent_nothing(buf, sizeof(buf)) == 0, "sent %s", buf);
	CHECK(orfa_pending(o) == 0, "pending %d", orfa_pending(o));
}

static void test_bad_lines(orfa_t *o)
{
	orfa_reply_t r;
	char buf[1024];
	char longline[300];

	CHECK(orfa_set_timeout(o, 0) == ORFA_E_ARG, "timeout 0");
	CHECK(orfa_set_timeout(o, 100) == ORFA_OK, "timeout");
	/* no reply: a timeout, the request still waits for its line */
	CHECK(intro(o, 0xAA, 0, 1) == ORFA_OK, "commit");
	sent(buf, sizeof(buf), 1);
	answer("SWAASR");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_TIMEOUT, "half a line");
	answer("07P\r\n");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_WRITE, "late SW");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.data[0] == 7, "late SR");

	/* a line over 127 characters, a line without CR, a line that answers
	 * something else: each is its request's ORFA_E_PROTOCOL, and the next
	 * line is the next request's */
	memset(longline, 'A', 200);
	strcpy(longline + 200, "\r\n");
	CHECK(orfa_version(o) == ORFA_OK && orfa_version(o) == ORFA_OK &&
	      orfa_version(o) == ORFA_OK && orfa_version(o) == ORFA_OK, "4 V");
	sent(buf, sizeof(buf), 4);
	answer(longline);
	answer("V1.1\n");
	answer("SWP\r\n");
	answer("V1.1\r\n");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_PROTOCOL, "200 characters");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_PROTOCOL, "no CR");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_PROTOCOL, "SWP to V");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_VERSION, "back in step");

	/* a line over 127 characters that arrives whole in one read, with the
	 * next request's reply behind it: the long line is its own request's
	 * ORFA_E_PROTOCOL and nothing of it reaches the next request */
	CHECK(orfa_version(o) == ORFA_OK, "V");
	CHECK(orfa_tr_start(o) == ORFA_OK && orfa_write(o, 0xAA, (const uint8_t *)"", 1) == ORFA_OK &&
	      orfa_read(o, 0xAA, 1) == ORFA_OK && orfa_tr_commit(o) == ORFA_OK, "SAA00SAB01P");
	sent(buf, sizeof(buf), 2);
	CHECK(strcmp(buf, "V\nSAA00SAB01P\n") == 0, "sent %s", buf);
	strcpy(longline + 200, "\r\nSWASR07P\r\n");
	answer(longline);
	CHECK(orfa_read_reply(o, &r) == ORFA_E_PROTOCOL, "200 characters in one read");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_WRITE && r.size == 1,
	      "the next request's SW");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_READ && r.size == 1 &&
	      r.data[0] == 7, "the next request's SR");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_STATE, "all read");
	/* the same, the long line split over two reads */
	CHECK(orfa_version(o) == ORFA_OK && orfa_version(o) == ORFA_OK, "2 V");
	sent(buf, sizeof(buf), 2);
	answer("AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_TIMEOUT, "half of it");
	answer("AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA"
	       "\r\nV1.1\r\n");
	CHECK(orfa_read_reply(o, &r) == ORFA_E_PROTOCOL, "180 characters in two reads");
	CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_VERSION, "in step");
	CHECK(orfa_set_timeout(o, 2000) == ORFA_OK, "timeout");
}

static void test_flow(orfa_t *o)
{
	orfa_reply_t r;
	char buf[4096];
	int i;

	/* 18 lines of 14 characters are 252, what the gateway's receive ring
	 * holds: all go out at once */
	for (i = 0; i < 18; i++) {
		CHECK(intro(o, 0xAA, 1, 6) == ORFA_OK, "commit %d", i);
	}
	CHECK(sent(buf, sizeof(buf), 18) == 18 * 14, "sent %zu", strlen(buf));
	/* the 19th waits for a reply: none comes, nothing is sent */
	CHECK(orfa_set_timeout(o, 100) == ORFA_OK, "timeout");
	CHECK(intro(o, 0xAA, 1, 6) == ORFA_E_TIMEOUT, "19th without a reply");
	CHECK(sent_nothing(buf, sizeof(buf)) == 0, "sent %s", buf);
	/* one reply makes room for it */
	answer("SWAASR000001000002P\r\n");
	CHECK(intro(o, 0xAA, 1, 6) == ORFA_OK, "19th");
	CHECK(sent(buf, sizeof(buf), 1) == 14, "sent %s", buf);
	CHECK(orfa_pending(o) == 2 * 19, "pending %d", orfa_pending(o));
	for (i = 1; i < 19; i++) {
		char line[32];

		snprintf(line, sizeof(line), "SWAASR0000%02X000002P\r\n", i + 1);
		answer(line);
	}
	for (i = 0; i < 19; i++) {
		CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_WRITE, "SW %d", i);
		CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_READ &&
		      r.data[2] == i + 1, "SR %d: %02X", i, r.data[2]);
	}
	CHECK(orfa_pending(o) == 0, "pending %d", orfa_pending(o));

	/* ORFA_QUEUE_MAX requests with their results unread: one more is
	 * refused once all their replies are in, and they are all still there */
	for (i = 0; i < ORFA_QUEUE_MAX; i++) {
		CHECK(orfa_version(o) == ORFA_OK, "V %d", i);
	}
	sent(buf, sizeof(buf), ORFA_QUEUE_MAX);
	for (i = 0; i < ORFA_QUEUE_MAX; i++) {
		answer("V1.1\r\n");
	}
	CHECK(orfa_version(o) == ORFA_E_FULL, "queue full");
	CHECK(sent_nothing(buf, sizeof(buf)) == 0, "sent %s", buf);
	for (i = 0; i < ORFA_QUEUE_MAX; i++) {
		CHECK(orfa_read_reply(o, &r) == ORFA_OK && r.type == ORFA_REPLY_VERSION, "V %d", i);
	}
	CHECK(orfa_read_reply(o, &r) == ORFA_E_STATE, "all read");
	CHECK(orfa_set_timeout(o, 2000) == ORFA_OK, "timeout");
}

static void test_hangup(orfa_t *o)
{
	orfa_reply_t r;

	CHECK(orfa_version(o) == ORFA_OK, "V");
	close(master);
	master = -1;
	CHECK(orfa_read_reply(o, &r) == ORFA_E_IO, "the other end closed");
}

int main(void)
{
	orfa_t *o = NULL;

	open_pty();
	test_open();
	test_rates_by_number();
	CHECK(orfa_open(&o, slave_path, 115200) == ORFA_OK, "open %s", slave_path);
	if (o != NULL) {
		test_exchange(o);
		test_bad_lines(o);
		test_flow(o);
		test_hangup(o);
		orfa_close(o);
	}
	printf("orfa-port: %d checks, %d failures\n", checks, failures);
	return failures != 0;
}
