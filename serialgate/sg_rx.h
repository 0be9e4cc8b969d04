/*
 * The serial line's receive ring: characters in from the receive interrupt,
 * out to the parser in the main loop. When the ring overflows (a host that
 * breaks the flow rule of docs/protocol.md), the characters lost are not
 * silently dropped: the ring writes what the parser needs so that every
 * request still gets exactly one reply, a lost one `ERROR 04` (docs/protocol.md, "Flow").
 *
 * Pure: no hardware, so it compiles and is tested on the host too. The
 * interrupt calls sg_rx_put(), the main loop sg_rx_get() and, with
 * interrupts off, sg_rx_close().
 */
#ifndef SG_RX_H
#define SG_RX_H

#include <stdbool.h>
#include <stdint.h>

/* 8-bit indices wrap for free. The ring holds 252 characters and keeps three
 * slots for the record of a lost run; with the line the parser holds while a
 * request executes, a host with fewer than 256 characters of requests
 * unanswered (docs/protocol.md, "Flow") never overflows it. */
#define SG_RX_SIZE 256
#define SG_RX_RECORD 3

/* What the ring writes in the place of lost characters (sg_parse.h gives the
 * parser's names of the same values; bytes >= 0x80 from the line are stored
 * as 0x7F, so none can look like them):
 * - 0x80, lo, hi: line ends were lost; the line going on before them is gone
 *   and lo | hi << 8 of the lines that ended within the run were requests
 *   (something but spaces in them, not a '#' comment), each `ERROR 04`.
 * - 0x81 in place of a line end: this line lost characters and is a request.
 * - 0x82 in place of a line end: this line lost characters but held nothing
 *   (spaces only) or was a comment: no reply, as for any such line. */
#define SG_RX_MARK_LOST      0x80
#define SG_RX_MARK_END_LOST  0x81
#define SG_RX_MARK_END_EMPTY 0x82

struct sg_rx {
	uint8_t buf[SG_RX_SIZE];
	volatile uint8_t head;     /* written by the interrupt */
	volatile uint8_t tail;     /* written by the main loop */
	volatile uint8_t losing;   /* characters are being lost */
	uint8_t ends_lost;         /* a line end was lost in this run */
	uint16_t requests_lost;    /* requests whose end was lost in this run */
	uint8_t line;              /* what is known of the line coming in */
};

/* The ring's state, open for two: the main loop's parser takes runs of
 * characters straight from buf (sg_parse_run() in front_poll(), tail moved
 * past them, as sg_rx_get() would one at a time), and the receive
 * interrupt's fast path (firmware/uart.c) stores a character as sg_rx_put()
 * would with a few registers. Its rule: while line == SG_RX_LINE_PLAIN (a line started,
 * something but spaces in it, not a comment, nothing lost; never so while
 * characters are being lost: sg_rx.c keeps that) and
 * (uint8_t)(tail - head - 1) > SG_RX_RECORD, a character from ' ' to 0x7F
 * is stored as is: buf[head] = c, head + 1, and so is a CR or LF, line
 * then 0. Anything else: sg_rx_put(). */
extern struct sg_rx sg_rx;
#define SG_RX_LINE_PLAIN 0x03
/* In line while a board's hold keeps received characters (firmware/uart.c,
 * BOARD_RX_BURST): the fast path's tests of line then fail, and the
 * character goes to the interrupt's whole handler, which hands the hold on
 * first. uart.c sets and clears it with interrupts off, before they are on
 * again after the hold changed; sg_rx.c neither looks at it nor keeps it. */
#define SG_RX_LINE_HELD 0x80

void sg_rx_init(void);

/* One received character (interrupt). */
void sg_rx_put(uint8_t c);

/* The next character for the parser, or -1 if none is waiting. */
int16_t sg_rx_get(void);

/* A lost run that no character followed yet (the host went quiet) needs its
 * record written now, or the lost requests would wait for more input. */
bool sg_rx_losing(void);

/* With interrupts off, the ring empty: write that record. */
void sg_rx_close(void);

#endif
