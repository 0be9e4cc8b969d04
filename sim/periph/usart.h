/*
 * usart.h: the simulator's own model of one AVR USART (asynchronous mode),
 * replacing simavr 1.6's (wrong byte times, no URSEL, UDRE bug, no overrun:
 * see docs/simulator.md, "What simavr 1.6 gets wrong"). It takes over the
 * USART's registers after avr_init and paces both directions of the wire in
 * CPU cycles:
 *
 *   byte time = bit time * (1 start + data + parity + stop bits),
 *   bit time  = 16 * (UBRR + 1) cycles, 8 * (UBRR + 1) with U2X.
 *
 * Receive: bytes from the host are queued and put on the wire back to back;
 * 2-byte FIFO plus the shift register, DOR and a lost byte on overflow.
 * Bytes can also be scheduled at chosen cycles (usart_inject, the control
 * request `rx`); they own the wire at their cycles and host bytes wait for
 * a gap long enough for a whole byte.
 * Transmit: UDR buffer plus shift register; a byte reaches the host at the
 * end of its stop bit.
 * Pins: RXD carries the PC's frames and TXD the board's (usart_set_pin,
 * usart_set_tx_pin), edge by edge from cycle timers.
 */
#ifndef SIM_USART_H
#define SIM_USART_H

#include <stddef.h>
#include <stdint.h>

#include "sim_avr.h"
#include "sim_io.h"
#include "sim_interrupts.h"

#include "periph/sim_mcu.h"
#include "harness/trace.h"
#include "periph/sim_uart_line.h"

/* Bytes from the host waiting for the wire; the pty is read only while
 * there is room, so a fast host is slowed by the kernel's pty buffer. */
#define USART_HOST_QUEUE 4096

/* Bytes scheduled with usart_inject and not yet on the wire, at most. */
#define USART_INJECT_QUEUE 32768

typedef void (*usart_to_host_t)(void *param, uint8_t byte);

/* Drives a pin: LEVEL 0 or 1 from CYCLE on, or -1 to let it go (TXD when
 * the transmitter is off). */
typedef void (*usart_pin_t)(void *param, int level, avr_cycle_count_t cycle);

/* One direction's frames drawn on a pin, 8N1: start bit, eight data bits
 * LSB first, stop bit, each BIT cycles from the start bit's edge. */
typedef struct usart_wave_t {
	usart_pin_t pin;		/* NULL: no pin to draw on */
	void *param;
	int level;
	avr_cycle_count_t start;	/* the frame being drawn */
	uint32_t bit;
	uint8_t byte;
	int k;
} usart_wave_t;

/* One scheduled byte: its start bit begins at START, it takes CYCLES. */
typedef struct usart_inject_t {
	avr_cycle_count_t start;
	uint32_t cycles;
	uint8_t byte;
} usart_inject_t;

typedef struct usart_rx_slot_t {
	uint8_t data;
	uint8_t dor;
	uint8_t fe;
} usart_rx_slot_t;

typedef struct usart_t {
	avr_io_t io;			/* first: reset hook via avr_register_io */
	avr_t *avr;
	const sim_mcu_usart_t *regs;
	trace_t *trace;
	usart_to_host_t to_host;
	void *to_host_param;

	avr_int_vector_t vect_rxc, vect_udre, vect_txc;

	/* registers the model keeps itself (UCSRB lives in avr->data) */
	uint8_t ucsra;			/* TXC, UDRE, U2X, MPCM */
	uint8_t ucsrc;
	uint16_t ubrr;
	avr_cycle_count_t ubrrh_read_cycle;

	/* host -> wire -> receiver */
	uint8_t host_q[USART_HOST_QUEUE];
	size_t host_head, host_len;
	usart_inject_t inj_q[USART_INJECT_QUEUE];	/* scheduled, by start */
	size_t inj_head, inj_len;
	avr_cycle_count_t inj_end;	/* end of the last scheduled byte */
	int rx_timer_armed;		/* usart_rx_timer is registered */
	int rx_wire_busy;		/* a byte is on the wire now */
	avr_cycle_count_t rx_wire_end;	/* ... until the end of its stop bit */
	uint8_t rx_wire_byte;
	int rx_wire_valid;		/* the receiver was on at its start bit */
	int rx_wire_fast;		/* rates agree: the byte arrives whole */
	usart_rx_slot_t rx_fifo[2];
	uint8_t rx_fifo_len;
	int rx_shift_full;		/* complete frame waiting in the shifter */
	uint8_t rx_shift_byte;
	uint8_t rx_shift_fe;
	int rx_dor;			/* a frame was lost: DOR for the shifter's frame */
	uint8_t rx_last;
	uint32_t fe_read;		/* frames with FE the firmware took from UDR */
	uint32_t host_taken;		/* bytes taken from the PC's port (the pty) */
	uint32_t rx_lost;		/* frames lost to receive overrun (DOR) */

	/* The PC's side of the line: its rate (the pty's termios), the
	 * waveform of both directions and the receivers at either end that
	 * decode it when the two rates differ (sim_uart_line.h). */
	uint32_t host_baud;
	uint32_t host_bit;		/* cycles per bit at host_baud */
	sim_uart_line_t rx_line;		/* PC -> board */
	sim_uart_dec_t rx_dec;		/* the board's receiver */
	int rx_dec_armed;
	avr_cycle_count_t rxen_since;	/* RXEN last turned on */
	sim_uart_line_t tx_line;		/* board -> PC */
	sim_uart_dec_t pc_dec;		/* the PC's receiver */
	int pc_dec_armed;
	int tx_fast;			/* the byte in the shifter reaches the PC whole */
	usart_wave_t rxd;		/* the PC's frames on RXD */
	usart_wave_t txd;		/* the board's frames on TXD */
	int txd_owned;			/* the transmitter drives TXD */

	/* transmitter */
	int tx_buf_full;
	uint8_t tx_buf;
	int tx_shift_busy;
	uint8_t tx_shift_byte;

	uint32_t activity;		/* bumps on every byte on the wire */
} usart_t;

/* Take over the USART described by REGS on AVR (after avr_init). Bytes the
 * firmware sends go to TO_HOST at the end of their stop bit. */
void usart_init(usart_t *u, avr_t *avr, const sim_mcu_usart_t *regs,
		trace_t *trace, usart_to_host_t to_host, void *param);

/* Room left in the host queue. */
size_t usart_host_room(const usart_t *u);

/* Queue N bytes from the host (at most usart_host_room). */
void usart_host_send(usart_t *u, const uint8_t *buf, size_t n);

/* The first cycle at which usart_inject may start a byte: now, or the end
 * of the byte on the wire or of the last scheduled one if later. */
avr_cycle_count_t usart_inject_free_at(const usart_t *u);

/* Room left in the schedule of usart_inject, in bytes. */
size_t usart_inject_room(const usart_t *u);

/* Bytes scheduled and not yet on the wire. */
size_t usart_inject_pending(const usart_t *u);

/* Schedule N bytes (at most usart_inject_room) on the receive line, back to
 * back at the current byte time, the first start bit at cycle START (at or
 * after usart_inject_free_at). Returns the cycle the last stop bit ends, or
 * 0 when START or N break those rules (nothing is scheduled then). */
avr_cycle_count_t usart_inject(usart_t *u, avr_cycle_count_t start,
			       const uint8_t *buf, size_t n);

/* The PC's rate (baud), as its port's termios say; the line follows a
 * change from the next bit the PC sends. 0 is ignored. */
void usart_set_host_baud(usart_t *u, uint32_t baud);

/* Draw the PC's waveform on RXD through PIN (idle high from now on). */
void usart_set_pin(usart_t *u, usart_pin_t pin, void *param);

/* Draw the board's frames on TXD through PIN: while TXEN is on (and until
 * a pending byte has gone out after it went off) the transmitter owns the
 * pin, idle high, each byte from the cycle its shift register takes it at
 * the board's bit time; otherwise PIN gets -1 (the port decides). */
void usart_set_tx_pin(usart_t *u, usart_pin_t pin, void *param);

/* The board's bit time from UBRR/U2X, in cycles. */
uint32_t usart_board_bit(const usart_t *u);

/* Whether the firmware has its receiver on (RXEN). */
int usart_rxen(const usart_t *u);

/* Cycles one frame takes with the current UBRR/U2X/UCSRC settings. */
avr_cycle_count_t usart_byte_cycles(const usart_t *u);

#endif
