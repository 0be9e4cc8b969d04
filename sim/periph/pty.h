/*
 * pty.h: the board's serial port as a pseudo-terminal, reached by the PC
 * through a symlink. Single-threaded: the main loop calls pty_read and
 * pty_flush between simulation batches.
 */
#ifndef SIM_PTY_H
#define SIM_PTY_H

#include <stddef.h>
#include <stdint.h>

typedef struct pty_t {
	int master;		/* non-blocking; the simulator's end */
	int slave;		/* kept open so the master never sees a hangup */
	char slave_name[128];
	char *link;		/* symlink path, removed by pty_close */
	uint8_t *out;		/* bytes for the PC not yet taken by the kernel */
	size_t out_len, out_cap;
} pty_t;

/* Open a raw pty. 0, or -1 with errno set. */
int pty_open(pty_t *p);

/* Point LINK at the pty (replacing a stale link). 0, or -1 with errno. */
int pty_link(pty_t *p, const char *link);

/* Read up to N bytes from the PC; returns the count (0 when none). */
size_t pty_read(pty_t *p, uint8_t *buf, size_t n);

/* Queue one byte for the PC; pty_flush hands queued bytes to the kernel. */
void pty_write(pty_t *p, uint8_t byte);
void pty_flush(pty_t *p);

/* The PC's rate: the output speed of the pty's termios in baud (pyserial's
 * `baudrate`, standard or set through BOTHER), 0 if unknown. */
unsigned pty_baud(const pty_t *p);

/* Remove the link and close everything. */
void pty_close(pty_t *p);

#endif
