/*
 * control.h: the control socket (--control PATH): a unix stream socket
 * serviced from the main loop between batches; one request line, one reply
 * line (docs/simulator.md lists the commands). Several clients may be
 * connected at once; a client's `wait` holds back only its own later
 * requests, never the simulation.
 */
#ifndef SIM_CONTROL_H
#define SIM_CONTROL_H

#include <poll.h>
#include <stdint.h>

#include "sim_avr.h"

#include "boards/board_model.h"
#include "periph/pty.h"
#include "periph/twi_bus.h"
#include "periph/usart.h"
#include "parts/part.h"

#define CONTROL_CLIENTS 8
#define CONTROL_LINE 1024

/* What a client's reply waits for: a cycle (`wait N`), or the bus's byte
 * count (`wait i2c N WITHIN`), with the cycle as its bound. */
typedef struct control_wait_t {
	uint64_t until;		/* the cycle it ends at, or the bound's */
	uint32_t bytes;		/* twi_bus_t.bytes that ends it (modulo 2^32) */
	uint32_t n;		/* the bytes waited for (0: a cycle's wait) */
} control_wait_t;

typedef struct control_client_t {
	int fd;				/* -1: free */
	char in[CONTROL_LINE];
	size_t in_len;
	int overlong;			/* discarding a line that was too long */
	char *out;
	size_t out_len, out_cap;
	int waiting;
	control_wait_t wait;
} control_client_t;

#define CONTROL_MAX_BOARDS 16
#define CONTROL_FLAG_WATCHES 4	/* vectors whose flags `flag` watches, a board */

/* A board the requests can reach: the gateway (addr 0, first) or a slave,
 * named by its 8-bit address: `10/servo3`, `@10`. */
typedef struct control_board_t {
	uint8_t addr;
	avr_t *avr;
	board_model_t *bm;
	struct isr_watch_t *twi_isr;	/* its TWI interrupt's durations (`isr`), or NULL */
	struct flag_watch_t *flags[CONTROL_FLAG_WATCHES];	/* `flag`, made at its first */
} control_board_t;

typedef struct control_t {
	int fd;				/* listening socket, -1: off */
	char *path;
	avr_t *avr;			/* the gateway's: its cycle is world time */
	control_board_t board[CONTROL_MAX_BOARDS];
	int nboards;
	usart_t *usart;			/* the board's serial port (`rx`) */
	const pty_t *pty;		/* the PC's port: its rate, read at `rx` and `line` */
	control_client_t client[CONTROL_CLIENTS];
	uint32_t activity;		/* bumps on every request */
	twi_bus_t *bus;			/* the I2C bus (`i2c`) */
	const part_list_t *parts;	/* the parts on it (their own requests) */
} control_t;

/* Listen on PATH (an existing socket file there is replaced) for requests
 * about the gateway (AVR, BM, its serial port USART), the I2C bus BUS and
 * the PARTS on it. 0 or -1. */
int control_open(control_t *c, const char *path, avr_t *avr, board_model_t *bm,
		 usart_t *usart, twi_bus_t *bus, const part_list_t *parts);

/* Let the requests reach a slave board at ADDR (8-bit). 0 or -1 when full. */
int control_add_board(control_t *c, uint8_t addr, avr_t *avr, board_model_t *bm);

/* Accept, read, answer, send: never blocks. */
void control_poll(control_t *c);

/* True while some client waits for simulated time or bus bytes. */
int control_waiting(const control_t *c);

/* The earliest cycle a waiting client wants (UINT64_MAX when none): a
 * `wait`'s, or a `wait i2c`'s bound. */
uint64_t control_deadline(const control_t *c);

/* The fewest bus bytes a client's `wait i2c` still waits for, 0 when none
 * does: the run should stop after the quantum that many came in. */
uint32_t control_bytes_due(const control_t *c);

/* Add the socket's descriptors to PFD (room for MAX); returns how many. */
int control_pollfds(const control_t *c, struct pollfd *pfd, int max);

void control_close(control_t *c);

/* Answer one request LINE into OUT (no newline); exposed for tests. Returns
 * 1 when the reply must wait for *WAIT. */
int control_request(control_t *c, const char *line, char **out, size_t *len,
		    size_t *cap, control_wait_t *wait);

#endif
