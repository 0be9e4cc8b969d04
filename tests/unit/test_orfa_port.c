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
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
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

/* --- a gateway on the master side, in a child process --------------------------
 * orfa_open talks before it returns (it ends the board's partial line and
 * waits for V and L to be answered), so opens are served by a child: a
 * small gateway that holds `held` as the partial line a terminal left,
 * answers V, L, the count request SAA0000SAB01P and the short probe
 * SAA00SAB01P (7 drivers), ERROR 03 to anything else, nothing to an empty
 * line or a comment; with `noise`, it also sends a GPS's NMEA sentences and
 * bytes with no line end all the time; with `silent`, it answers nothing. */

enum { GW_ANSWER = 0, GW_SILENT = 1, GW_NOISE = 2 };

static void gw_reply(const char *line)
{
	const char *reply = "ERROR 03\r\n";
	char text[256];
	size_t n = 0;

	for (; *line != '\0'; line++) {
		if (*line != ' ' && n + 1 < sizeof(text)) {
			text[n++] = *line;
		}
	}
	text[n] = '\0';
	if (n == 0 || text[0] == '#') {
		return;
	}
	if (strcmp(text, "V") == 0) {
		reply = "V1.1\r\n";
	} else if (strcmp(text, "L") == 0) {
		reply = "LAA\r\n";
	} else if (strcmp(text, "SAA0000SAB01P") == 0 || strcmp(text, "SAA00SAB01P") == 0) {
		reply = strlen(text) == 13 ? "SWAASR07P\r\n" : "SWASR07P\r\n";
	}
	answer(reply);
}

static pid_t gw_start(const char *held, int mode)
{
	pid_t pid = fork();
	char line[256];
	size_t n;

	if (pid < 0) {
		perror("fork");
		exit(2);
	}
	if (pid > 0) {
		return pid;
	}
	alarm(20);              /* never outlive a test that failed to stop it */
	snprintf(line, sizeof(line), "%s", held);
	n = strlen(line);
	for (;;) {
		struct pollfd pfd = {master, POLLIN, 0};
		char buf[256];
		ssize_t got;

		if (mode & GW_NOISE) {
			answer("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n"
			       "\x87\xfe\x01garbage with no line end ");
		}
		if (poll(&pfd, 1, 1) <= 0) {
			continue;
		}
		got = read(master, buf, sizeof(buf));
		if (got <= 0) {
			usleep(1000);   /* no slave side open just now */
			continue;
		}
		for (ssize_t i = 0; i < got; i++) {
			if (buf[i] == '\n' || buf[i] == '\r') {
				line[n] = '\0';
				if (!(mode & GW_SILENT)) {
					gw_reply(line);
				}
				n = 0;
			} else if (n + 1 < sizeof(line)) {
				line[n++] = buf[i];
			}
		}
	}
}

static void gw_stop(pid_t pid)
{
	kill(pid, SIGKILL);
	waitpid(pid, NULL, 0);
}

/* orfa_open with the child gateway answering, stopped after it. */
static int open_served(orfa_t **o, long baud)
{
	pid_t pid = gw_start("", GW_ANSWER);
	int rc = orfa_open(o, slave_path, baud);

	gw_stop(pid);
	return rc;
}

static long ms_now(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
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
 * name (230400 and 460800: B230400, B460800): the port's rate is what was
 * asked, read on a descriptor of our own. */
static void test_rates_by_number(void)
{
	static const long rates[] = {14400, 28800, 76800, 115200, 460800, 76800, 230400};
	int fd = open(slave_path, O_RDWR | O_NOCTTY);
	size_t i;

	CHECK(fd >= 0, "open %s: %s", slave_path, strerror(errno));
	for (i = 0; i < sizeof(rates) / sizeof(rates[0]) && fd >= 0; i++) {
		orfa_t *o = NULL;
		int rc = open_served(&o, rates[i]);

		CHECK(rc == ORFA_OK, "open at %ld: %d (%s)", rates[i], rc, strerror(errno));
		CHECK(orfa_speed_get(fd) == rates[i], "rate %ld: the port says %ld", rates[i],
		      orfa_speed_get(fd));
		orfa_close(o);
	}
	if (fd >= 0) {
		close(fd);
	}
}

/* The open ends whatever partial line the board holds and drops its reply:
 * the first request is answered as itself. A held `V` or `L` gives a reply
 * like the open's own, and nothing of it is left either. What the open
 * sent: LF, then V and L. */
static void test_open_ends_partial_line(void)
{
	static const char *const held[] = {"", "S AA 0", "SAA0000SAB01", "V", "L", "# a comment",
					   "zz"};
	size_t i;

	for (i = 0; i < sizeof(held) / sizeof(held[0]); i++) {
		pid_t pid = gw_start(held[i], GW_ANSWER);
		orfa_t *o = NULL;
		orfa_reply_t r;
		int rc = orfa_open(&o, slave_path, 115200);

		CHECK(rc == ORFA_OK, "'%s' held: open %d", held[i], rc);
		if (rc == ORFA_OK) {
			CHECK(intro(o, 0xAA, 0, 1) == ORFA_OK, "'%s': commit", held[i]);
			rc = orfa_read_reply(o, &r);
			CHECK(rc == ORFA_OK && r.type == ORFA_REPLY_WRITE, "'%s' held: first result %d",
			      held[i], rc);
			rc = orfa_read_reply(o, &r);
			CHECK(rc == ORFA_OK && r.type == ORFA_REPLY_READ && r.data[0] == 7,
			      "'%s' held: second result %d", held[i], rc);
			orfa_close(o);
		}
		gw_stop(pid);
	}
	/* the bytes of the open, the test itself the gateway that does not
	 * answer (a slave side held open, so that the master side has one
	 * while the child's open comes and goes) */
	{
		char buf[64];
		int fd = open(slave_path, O_RDWR | O_NOCTTY);
		int status = -1;
		pid_t pid = fork();

		if (pid == 0) {
			orfa_t *o = NULL;

			_exit(orfa_open(&o, slave_path, 115200) == ORFA_E_TIMEOUT ? 0 : 1);
		}
		sent(buf, sizeof(buf), 3);
		CHECK(strcmp(buf, "!\nV\nL\n") == 0, "the open sent '%s'", buf);
		waitpid(pid, &status, 0);
		CHECK(status == 0, "unanswered, the open timed out: status %d", status);
		close(fd);
	}
}

/* Bounded, whatever the line carries: nothing at all, or a stream of NMEA
 * sentences and junk with no gateway behind it: ORFA_E_TIMEOUT within
 * ORFA_TIMEOUT_MS (and a little), no handle. With a gateway behind the
 * noise, the open finds its replies among it. */
static void test_open_bounded(void)
{
	static const int modes[] = {GW_SILENT, GW_SILENT | GW_NOISE};
	size_t i;

	for (i = 0; i < sizeof(modes) / sizeof(modes[0]); i++) {
		pid_t pid = gw_start("S AA 0", modes[i]);
		orfa_t *o = (orfa_t *)1;
		long t0 = ms_now();
		int rc = orfa_open(&o, slave_path, 115200);
		long took = ms_now() - t0;

		gw_stop(pid);
		CHECK(rc == ORFA_E_TIMEOUT && errno == ETIMEDOUT && o == NULL,
		      "mode %d: open %d (%s)", modes[i], rc, strerror(errno));
		CHECK(took >= ORFA_TIMEOUT_MS - 50 && took < ORFA_TIMEOUT_MS + 500,
		      "mode %d: the open took %ld ms", modes[i], took);
	}
	{
		pid_t pid = gw_start("S AA 0", GW_NOISE);
		orfa_t *o = NULL;
		int rc = orfa_open(&o, slave_path, 115200);

		gw_stop(pid);
		CHECK(rc == ORFA_OK, "a gateway behind the noise: open %d", rc);
		orfa_close(o);
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
	test_open_ends_partial_line();
	test_open_bounded();
	CHECK(open_served(&o, 115200) == ORFA_OK, "open %s", slave_path);
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
