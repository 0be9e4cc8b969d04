/*
 * sim_uart_line.h: one direction of a serial line as the frames put on it
 * (8N1, each at its sender's bit time), and a receiver that decodes that
 * waveform at its own bit time the way the AVR's USART does: start-bit
 * detection on a falling edge, each bit taken as the majority of three
 * samples around its centre (the datasheet's samples 8, 9 and 10 of 16),
 * FE when the stop bit samples low. Pure: cycles in, bytes out.
 */
#ifndef SIM_UART_LINE_H
#define SIM_UART_LINE_H

#include <stdint.h>

#include "sim_avr.h"

/* Frames kept: enough for the slowest receiver (2400 baud) to look back over
 * one of its frames of a sender 48 times faster, with a wide margin. */
#define UART_LINE_FRAMES 1024

typedef struct sim_uart_frame_t {
	avr_cycle_count_t start;	/* the start bit's falling edge */
	uint32_t bit;			/* the sender's bit time, cycles */
	uint8_t byte;
	uint8_t skip;			/* taken whole by the fast path */
} sim_uart_frame_t;

typedef struct sim_uart_line_t {
	sim_uart_frame_t f[UART_LINE_FRAMES];	/* oldest first, a ring */
	unsigned head, len;
} sim_uart_line_t;

typedef struct sim_uart_dec_t {
	int busy;			/* inside a frame since t0 */
	avr_cycle_count_t t0;
	avr_cycle_count_t cursor;	/* falling edges before this are gone */
	uint32_t bit;			/* the receiver's bit time for this frame */
} sim_uart_dec_t;

/* A decoded frame: its last sample at WHEN, FE when the stop bit was low. */
typedef void (*sim_uart_dec_emit_t)(void *param, avr_cycle_count_t when,
				avr_cycle_count_t t0, uint8_t byte, int fe);

void sim_uart_line_reset(sim_uart_line_t *l);

/* A frame whose start bit begins at START (not before the last one's end). */
void sim_uart_line_push(sim_uart_line_t *l, avr_cycle_count_t start, uint32_t bit,
		    uint8_t byte, int skip);

/* The line's level at cycle T (1 = idle/mark). */
int sim_uart_line_level(const sim_uart_line_t *l, avr_cycle_count_t t);

/* Level of bit K (0 start, 1..8 data LSB first, 9 stop) of a frame. */
static inline int sim_uart_frame_bit(uint8_t byte, int k)
{
	return k == 0 ? 0 : k <= 8 ? (byte >> (k - 1)) & 1 : 1;
}

/* Decode the line up to cycle UNTIL with bit time BIT (taken at each start
 * bit), calling EMIT per frame. Returns the cycle at which it must run again
 * to finish the frame it is in or one already on the line (0: nothing until
 * a new frame is pushed). */
avr_cycle_count_t sim_uart_dec_run(sim_uart_dec_t *d, const sim_uart_line_t *l, uint32_t bit,
			       avr_cycle_count_t until, sim_uart_dec_emit_t emit,
			       void *param);

/* Forget everything before cycle T (the receiver was off, or took a frame
 * by the fast path). */
static inline void sim_uart_dec_skip_to(sim_uart_dec_t *d, avr_cycle_count_t t)
{
	d->busy = 0;
	if (t > d->cursor) {
		d->cursor = t;
	}
}

#endif
