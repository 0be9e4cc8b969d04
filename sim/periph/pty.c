/*
 * pty.c: own pty bridge. simavr's uart_pty part uses a fixed machine-wide
 * link and a reader thread that gives up; this one is a plain non-blocking
 * master polled by the main loop.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#include "periph/pty.h"

/* Bytes for the PC beyond this, with nobody reading, are dropped like on
 * a wire with nothing plugged in. */
#define PTY_OUT_MAX (1u << 20)

int pty_open(pty_t *p)
{
	struct termios tio;

	memset(p, 0, sizeof(*p));
	p->master = p->slave = -1;
	/* posix_openpt rather than openpty(): <pty.h> has the name of this
	 * module's own header (periph/pty.h). */
	p->master = posix_openpt(O_RDWR | O_NOCTTY);
	if (p->master < 0 || grantpt(p->master) < 0 || unlockpt(p->master) < 0 ||
	    ptsname_r(p->master, p->slave_name, sizeof(p->slave_name)) != 0) {
		return -1;
	}
	p->slave = open(p->slave_name, O_RDWR | O_NOCTTY);
	if (p->slave < 0) {
		return -1;
	}
	if (tcgetattr(p->slave, &tio) == 0) {
		cfmakeraw(&tio);
		/* ORFA's default rate, until the PC sets its own. */
		cfsetspeed(&tio, B115200);
		tcsetattr(p->slave, TCSANOW, &tio);
	}
	fcntl(p->master, F_SETFL, fcntl(p->master, F_GETFL) | O_NONBLOCK);
	fcntl(p->master, F_SETFD, FD_CLOEXEC);
	fcntl(p->slave, F_SETFD, FD_CLOEXEC);
	return 0;
}

int pty_link(pty_t *p, const char *link)
{
	struct stat st;

	/* Replace a stale link left by a killed run, but never a real file. */
	if (lstat(link, &st) == 0 && S_ISLNK(st.st_mode)) {
		unlink(link);
	}
	if (symlink(p->slave_name, link) < 0) {
		return -1;
	}
	p->link = strdup(link);
	return 0;
}

size_t pty_read(pty_t *p, uint8_t *buf, size_t n)
{
	ssize_t r = read(p->master, buf, n);

	return r > 0 ? (size_t)r : 0;
}

void pty_write(pty_t *p, uint8_t byte)
{
	if (p->out_len == p->out_cap) {
		if (p->out_cap >= PTY_OUT_MAX) {
			return;
		}
		p->out_cap = p->out_cap ? p->out_cap * 2 : 256;
		p->out = realloc(p->out, p->out_cap);
		if (!p->out) {
			perror("orfa-sim: pty buffer");
			exit(1);
		}
	}
	p->out[p->out_len++] = byte;
}

void pty_flush(pty_t *p)
{
	if (!p->out_len) {
		return;
	}
	ssize_t w = write(p->master, p->out, p->out_len);
	if (w > 0) {
		memmove(p->out, p->out + w, p->out_len - (size_t)w);
		p->out_len -= (size_t)w;
	}
}

void pty_close(pty_t *p)
{
	if (p->link) {
		unlink(p->link);
		free(p->link);
		p->link = NULL;
	}
	if (p->master >= 0) {
		close(p->master);
	}
	if (p->slave >= 0) {
		close(p->slave);
	}
	free(p->out);
	p->master = p->slave = -1;
}
