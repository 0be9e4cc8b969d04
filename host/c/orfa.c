/*
 * The ORFA host library on a POSIX serial port: the request lines of
 * orfa_line.c sent, the reply lines read back with poll() and matched to
 * the requests in order (every request gets exactly one reply line).
 */
#define _POSIX_C_SOURCE 200809L

#include "orfa.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "orfa_speed.h"
#include "serialgate/sg_rx.h"

/* Characters of requests the gateway holds unanswered without overflowing
 * its receive ring (docs/protocol.md, "Flow"): the ring's room less the
 * slots it keeps for a lost run's record and one spare. */
#define ORFA_FLOW_CHARS (SG_RX_SIZE - SG_RX_RECORD - 1)

/* A request sent, and its reply line once received. */
typedef struct {
	orfa_req_t req;
	int bad;                        /* the line received was no reply */
	char reply[ORFA_REPLY_MAX + 1];
	size_t reply_len;
} pending_t;

struct orfa {
	int fd;
	struct termios saved;
	int timeout_ms;
	int code;                       /* protocol code of the last ERROR */
	orfa_req_t tr;                  /* the transaction being built */
	int tr_open;
	pending_t queue[ORFA_QUEUE_MAX];
	size_t head;
	size_t count;                   /* requests in the queue */
	size_t answered;                /* of them, from head, with a reply line */
	orfa_reply_t results[ORFA_FRAMES_MAX];  /* of the request being read */
	size_t nresults;
	size_t next;
	char rx[2 * (ORFA_REPLY_MAX + 2)];
	size_t rx_len;
	int rx_skip;                    /* dropping the rest of an over-long line */
};

/* Highest rate asked for by number (a rate without a Bxxx name). */
#define ORFA_BAUD_MAX 4000000L

/* The Bxxx name of BAUD in *SP, or B0 for a rate set by number after
 * tcsetattr (14400, 28800, 76800: rates the gateway can be built for). */
static int speed_of(long baud, speed_t *sp)
{
	static const struct {
		long baud;
		speed_t speed;
	} rates[] = {
		{2400, B2400}, {4800, B4800}, {9600, B9600}, {19200, B19200},
		{38400, B38400}, {57600, B57600}, {115200, B115200}, {230400, B230400},
#ifdef B460800
		{460800, B460800},      /* Linux's; where termios has none, by number */
#endif
	};
	size_t i;

	for (i = 0; i < sizeof(rates) / sizeof(rates[0]); i++) {
		if (rates[i].baud == baud) {
			*sp = rates[i].speed;
			return ORFA_OK;
		}
	}
	*sp = B0;
	return baud > 0 && baud <= ORFA_BAUD_MAX ? ORFA_OK : ORFA_E_ARG;
}

static long now_ms(void);
static int read_line(orfa_t *o, char *line, size_t *len, long deadline);

/* Brings the line in step after the open (docs/c-library.md, "Opening"):
 * `!` LF ends whatever partial line the board holds (someone typed `S AA 0`
 * in a terminal; a program left mid-line) as an error, so that nothing of it
 * runs, even a request that lacked only its line end (`!` is no command
 * letter, no hex digit, and nothing may follow a complete command); then `V`
 * and `L` (both only read).
 * The board answers the ended line (or not: it was empty or a comment), then
 * V, then L, so the first L reply after a V reply is ours, whatever the
 * partial line was (a `V` or an `L` too) and whatever lines came before.
 * Everything up to it is dropped. Bounded: ORFA_TIMEOUT_MS in all, however
 * much the line carries. */
static int resync(orfa_t *o)
{
	static const char sync[] = "!\nV\nL\n";
	long deadline = now_ms() + ORFA_TIMEOUT_MS;
	orfa_req_t v, l;
	orfa_reply_t results[ORFA_FRAMES_MAX];
	char line[ORFA_REPLY_MAX + 1];
	size_t len;
	size_t done = 0;
	int seen_v = 0;
	int code;

	orfa_req_version(&v);
	orfa_req_local(&l, -1);
	while (done < sizeof(sync) - 1) {
		ssize_t n = write(o->fd, sync + done, sizeof(sync) - 1 - done);

		if (n < 0) {
			if (errno == EINTR) {
				continue;
			}
			return ORFA_E_IO;
		}
		done += (size_t)n;
	}
	for (;;) {
		int rc = read_line(o, line, &len, deadline);

		if (rc == ORFA_E_PROTOCOL) {
			continue;               /* no reply of the gateway's: dropped */
		}
		if (rc != ORFA_OK) {
			return rc;
		}
		if (seen_v && orfa_reply_parse(&l, line, len, results, &code) == 1) {
			return ORFA_OK;
		}
		if (orfa_reply_parse(&v, line, len, results, &code) == 1) {
			seen_v = 1;
		}
	}
}

int orfa_open(orfa_t **out, const char *path, long baud)
{
	struct termios t;
	speed_t sp;
	orfa_t *o;
	int flags;
	int saved_errno;
	int rc = ORFA_E_IO;
	int changed = 0;                        /* the port's settings are ours */

	if (out == NULL || path == NULL || speed_of(baud, &sp) != ORFA_OK) {
		errno = EINVAL;
		return ORFA_E_ARG;
	}
	*out = NULL;
	o = calloc(1, sizeof(*o));
	if (o == NULL) {
		return ORFA_E_IO;
	}
	/* O_NONBLOCK: a port waiting for carrier must not hang the open */
	o->fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK);
	if (o->fd < 0) {
		goto fail;
	}
	flags = fcntl(o->fd, F_GETFL);
	if (flags < 0 || fcntl(o->fd, F_SETFL, flags & ~O_NONBLOCK) < 0 ||
	    tcgetattr(o->fd, &o->saved) < 0) {
		goto fail;
	}
	/* raw 8N1 (cfmakeraw is not POSIX): no echo, no line editing, no
	 * CR/LF translation, no flow control, reads as bytes come */
	t = o->saved;
	t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL |
				 IXON | IXOFF | INPCK);
	t.c_oflag &= ~(tcflag_t)OPOST;
	t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
	t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB);
	t.c_cflag |= CS8 | CLOCAL | CREAD;
	t.c_cc[VMIN] = 1;
	t.c_cc[VTIME] = 0;
	if (sp != B0 && (cfsetispeed(&t, sp) < 0 || cfsetospeed(&t, sp) < 0)) {
		goto fail;
	}
	if (tcsetattr(o->fd, TCSANOW, &t) < 0) {
		goto fail;
	}
	changed = 1;
	if (sp == B0 && orfa_speed_set(o->fd, baud) < 0) {
		if (errno == ENOTSUP) {                 /* no rates by number here */
			rc = ORFA_E_ARG;
			errno = EINVAL;
		}
		goto fail;
	}
	if (tcflush(o->fd, TCIOFLUSH) < 0) {
		goto fail;
	}
	o->timeout_ms = ORFA_TIMEOUT_MS;
	rc = resync(o);
	if (rc != ORFA_OK) {
		if (rc == ORFA_E_TIMEOUT) {
			errno = ETIMEDOUT;
		}
		goto fail;
	}
	*out = o;
	return ORFA_OK;
fail:
	saved_errno = errno;
	if (changed) {
		tcsetattr(o->fd, TCSANOW, &o->saved);
	}
	if (o->fd >= 0) {
		close(o->fd);
	}
	free(o);
	errno = saved_errno;
	return rc;
}

void orfa_close(orfa_t *o)
{
	if (o == NULL) {
		return;
	}
	tcsetattr(o->fd, TCSANOW, &o->saved);
	close(o->fd);
	free(o);
}

int orfa_set_timeout(orfa_t *o, int ms)
{
	if (o == NULL || ms <= 0) {
		return ORFA_E_ARG;
	}
	o->timeout_ms = ms;
	return ORFA_OK;
}

/* --- lines in --------------------------------------------------------------- */

static long now_ms(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (long)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

/* One line from the port into `line` (CR LF removed) by `deadline` (now_ms()
 * time): ORFA_OK; ORFA_E_PROTOCOL for a line that is over the reply limit or
 * not ended by CR LF (it is consumed: the next line is the next reply);
 * ORFA_E_TIMEOUT (what came of the line is kept) or ORFA_E_IO. */
static int read_line(orfa_t *o, char *line, size_t *len, long deadline)
{
	for (;;) {
		char *lf = memchr(o->rx, '\n', o->rx_len);
		struct pollfd pfd;
		long left;
		ssize_t n;

		if (lf != NULL) {
			size_t end = (size_t)(lf - o->rx);
			int rc = ORFA_OK;

			/* over the limit (whether it came in one read or
			 * several), without CR: no reply, and never copied */
			if (o->rx_skip || end == 0 || o->rx[end - 1] != '\r' ||
			    end - 1 > ORFA_REPLY_MAX) {
				rc = ORFA_E_PROTOCOL;
			} else {
				*len = end - 1;
				memcpy(line, o->rx, *len);
			}
			o->rx_skip = 0;
			o->rx_len -= end + 1;
			memmove(o->rx, lf + 1, o->rx_len);
			return rc;
		}
		if (o->rx_len > ORFA_REPLY_MAX + 1) {
			/* 127 characters and CR, and no LF yet: no reply of ours */
			o->rx_skip = 1;
			o->rx_len = 0;
		}
		left = deadline - now_ms();
		if (left <= 0) {
			return ORFA_E_TIMEOUT;
		}
		pfd.fd = o->fd;
		pfd.events = POLLIN;
		pfd.revents = 0;
		n = poll(&pfd, 1, (int)left);
		if (n < 0) {
			if (errno == EINTR) {
				continue;
			}
			return ORFA_E_IO;
		}
		if (n == 0) {
			continue;
		}
		n = read(o->fd, o->rx + o->rx_len, sizeof(o->rx) - o->rx_len);
		if (n < 0) {
			if (errno == EINTR || errno == EAGAIN) {
				continue;
			}
			return ORFA_E_IO;
		}
		if (n == 0) {
			/* the other end hung up */
			errno = EIO;
			return ORFA_E_IO;
		}
		o->rx_len += (size_t)n;
	}
}

static pending_t *entry(orfa_t *o, size_t i)
{
	return &o->queue[(o->head + i) % ORFA_QUEUE_MAX];
}

/* The next reply line, to the oldest request that has none. */
static int receive(orfa_t *o)
{
	pending_t *p = entry(o, o->answered);
	int rc = read_line(o, p->reply, &p->reply_len, now_ms() + o->timeout_ms);

	if (rc == ORFA_E_PROTOCOL) {
		p->bad = 1;
	} else if (rc != ORFA_OK) {
		return rc;
	}
	o->answered++;
	return ORFA_OK;
}

/* --- requests out ------------------------------------------------------------- */

static size_t unanswered_chars(orfa_t *o)
{
	size_t i;
	size_t sum = 0;

	for (i = o->answered; i < o->count; i++) {
		sum += entry(o, i)->req.len;
	}
	return sum;
}

static int send_req(orfa_t *o, const orfa_req_t *r)
{
	size_t done = 0;
	pending_t *p;

	while (o->count == ORFA_QUEUE_MAX || unanswered_chars(o) + r->len > ORFA_FLOW_CHARS) {
		int rc;

		if (o->answered == o->count) {
			return ORFA_E_FULL;
		}
		rc = receive(o);
		if (rc != ORFA_OK) {
			return rc;
		}
	}
	while (done < r->len) {
		ssize_t n = write(o->fd, r->text + done, r->len - done);

		if (n < 0) {
			if (errno == EINTR) {
				continue;
			}
			return ORFA_E_IO;
		}
		done += (size_t)n;
	}
	p = entry(o, o->count);
	p->req = *r;
	p->bad = 0;
	p->reply_len = 0;
	o->count++;
	return ORFA_OK;
}

int orfa_tr_start(orfa_t *o)
{
	if (o == NULL) {
		return ORFA_E_ARG;
	}
	orfa_req_start(&o->tr);
	o->tr_open = 1;
	return ORFA_OK;
}

int orfa_write(orfa_t *o, uint8_t address, const uint8_t *buf, size_t len)
{
	if (o == NULL) {
		return ORFA_E_ARG;
	}
	if (!o->tr_open) {
		return ORFA_E_STATE;
	}
	return orfa_req_write(&o->tr, address, buf, len);
}

int orfa_read(orfa_t *o, uint8_t address, size_t count)
{
	if (o == NULL) {
		return ORFA_E_ARG;
	}
	if (!o->tr_open) {
		return ORFA_E_STATE;
	}
	return orfa_req_read(&o->tr, address, count);
}

int orfa_tr_commit(orfa_t *o)
{
	int rc;

	if (o == NULL) {
		return ORFA_E_ARG;
	}
	if (!o->tr_open) {
		return ORFA_E_STATE;
	}
	/* the transaction ends here, sent or refused as a whole */
	o->tr_open = 0;
	rc = orfa_req_end(&o->tr);
	if (rc != ORFA_OK) {
		return rc;
	}
	return send_req(o, &o->tr);
}

static int send_command(orfa_t *o, int rc, const orfa_req_t *r)
{
	if (rc != ORFA_OK) {
		return rc;
	}
	return send_req(o, r);
}

int orfa_version(orfa_t *o)
{
	orfa_req_t r;

	if (o == NULL) {
		return ORFA_E_ARG;
	}
	return send_command(o, orfa_req_version(&r), &r);
}

int orfa_clear(orfa_t *o)
{
	orfa_req_t r;

	if (o == NULL) {
		return ORFA_E_ARG;
	}
	return send_command(o, orfa_req_clear(&r), &r);
}

int orfa_local(orfa_t *o, int addr)
{
	orfa_req_t r;

	if (o == NULL) {
		return ORFA_E_ARG;
	}
	return send_command(o, orfa_req_local(&r, addr), &r);
}

int orfa_clock(orfa_t *o, long khz)
{
	orfa_req_t r;

	if (o == NULL) {
		return ORFA_E_ARG;
	}
	return send_command(o, orfa_req_clock(&r, khz), &r);
}

/* --- results ------------------------------------------------------------------------ */

int orfa_read_reply(orfa_t *o, orfa_reply_t *reply)
{
	pending_t *p;
	int n;

	if (o == NULL || reply == NULL) {
		return ORFA_E_ARG;
	}
	if (o->next < o->nresults) {
		*reply = o->results[o->next++];
		return ORFA_OK;
	}
	if (o->count == 0) {
		return ORFA_E_STATE;
	}
	if (o->answered == 0) {
		int rc = receive(o);

		if (rc != ORFA_OK) {
			return rc;
		}
	}
	p = entry(o, 0);
	o->head = (o->head + 1) % ORFA_QUEUE_MAX;
	o->count--;
	o->answered--;
	o->nresults = 0;
	o->next = 0;
	if (p->bad) {
		return ORFA_E_PROTOCOL;
	}
	n = orfa_reply_parse(&p->req, p->reply, p->reply_len, o->results, &o->code);
	if (n < 0) {
		return n;
	}
	o->nresults = (size_t)n;
	*reply = o->results[o->next++];
	return ORFA_OK;
}

int orfa_reply_code(const orfa_t *o)
{
	return o == NULL ? 0 : o->code;
}

int orfa_pending(const orfa_t *o)
{
	size_t i;
	size_t sum;

	if (o == NULL) {
		return 0;
	}
	sum = o->nresults - o->next;
	for (i = 0; i < o->count; i++) {
		sum += o->queue[(o->head + i) % ORFA_QUEUE_MAX].req.nframes;
	}
	return (int)sum;
}
