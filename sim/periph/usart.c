/*
 * usart.c: USART model. Flags are level conditions recomputed by
 * usart_sync() after every change; simavr's vector table only sees the
 * result (see the note on interrupts there).
 */
#include <string.h>

#include "sim_regbit.h"

#include "periph/io_hook.h"
#include "periph/usart.h"
#include "simavr16/interrupt.h"

/* Register bits (datasheet names; the same on ATmega32 and ATmega128). */
enum {
	UCSRA_RXC = 7, UCSRA_TXC = 6, UCSRA_UDRE = 5, UCSRA_FE = 4,
	UCSRA_DOR = 3, UCSRA_PE = 2, UCSRA_U2X = 1, UCSRA_MPCM = 0,
	UCSRB_RXCIE = 7, UCSRB_TXCIE = 6, UCSRB_UDRIE = 5, UCSRB_RXEN = 4,
	UCSRB_TXEN = 3, UCSRB_UCSZ2 = 2, UCSRB_RXB8 = 1, UCSRB_TXB8 = 0,
	UCSRC_URSEL = 7, UCSRC_UMSEL = 6, UCSRC_UPM1 = 5, UCSRC_UPM0 = 4,
	UCSRC_USBS = 3, UCSRC_UCSZ1 = 2, UCSRC_UCSZ0 = 1, UCSRC_UCPOL = 0,
};

#define BIT(b) (1u << (b))

static inline uint8_t usart_ucsrb(const usart_t *u)
{
	return u->avr->data[u->regs->ucsrb];
}

avr_cycle_count_t usart_byte_cycles(const usart_t *u)
{
	static const uint8_t data_bits[8] = { 5, 6, 7, 8, 8, 8, 8, 9 };
	unsigned ucsz = ((u->ucsrc >> UCSRC_UCSZ0) & 3) |
			((usart_ucsrb(u) & BIT(UCSRB_UCSZ2)) ? 4 : 0);
	unsigned bits = 1 + data_bits[ucsz] +
			((u->ucsrc & BIT(UCSRC_UPM1)) ? 1 : 0) +
			((u->ucsrc & BIT(UCSRC_USBS)) ? 2 : 1);
	unsigned per_bit = (u->ucsra & BIT(UCSRA_U2X)) ? 8 : 16;

	return (avr_cycle_count_t)bits * per_bit * (u->ubrr + 1u);
}

int usart_rxen(const usart_t *u)
{
	return !!(usart_ucsrb(u) & BIT(UCSRB_RXEN));
}

uint32_t usart_board_bit(const usart_t *u)
{
	return ((u->ucsra & BIT(UCSRA_U2X)) ? 8u : 16u) * (u->ubrr + 1u);
}

/* The PC sends 8N1 at its own rate. */
static avr_cycle_count_t usart_host_byte_cycles(const usart_t *u)
{
	return 10ull * u->host_bit;
}

static uint8_t usart_ucsra(const usart_t *u)
{
	uint8_t v = u->ucsra & (BIT(UCSRA_TXC) | BIT(UCSRA_UDRE) |
				BIT(UCSRA_U2X) | BIT(UCSRA_MPCM));

	if (u->rx_fifo_len) {
		v |= BIT(UCSRA_RXC);
		if (u->rx_fifo[0].dor) {
			v |= BIT(UCSRA_DOR);
		}
		if (u->rx_fifo[0].fe) {
			v |= BIT(UCSRA_FE);
		}
	}
	return v;
}

/*
 * Interrupts. simavr latches a vector only if it is enabled when raised,
 * and forgets it once the ISR is entered; the USART's flags are levels
 * (RXC until UDR is emptied, UDRE while the buffer is free). So after every
 * change, on enable bit changes and on RETI, a vector is raised again while
 * its flag and enable bit are both set, and withdrawn when its flag drops
 * (with its entries in simavr 1.6's queue: simavr16/interrupt.h).
 */
static void usart_sync_vector(usart_t *u, avr_int_vector_t *v, int flag)
{
	avr_t *avr = u->avr;

	if (flag) {
		if (!v->pending && avr_regbit_get(avr, v->enable)) {
			avr_raise_interrupt(avr, v);
		}
	} else if (v->pending) {
		simavr16_withdraw_interrupt(avr, v);
	}
}

static void usart_sync(usart_t *u)
{
	uint8_t a = usart_ucsra(u);

	u->avr->data[u->regs->ucsra] = a;
	usart_sync_vector(u, &u->vect_rxc, a & BIT(UCSRA_RXC));
	usart_sync_vector(u, &u->vect_udre, a & BIT(UCSRA_UDRE));
	usart_sync_vector(u, &u->vect_txc, a & BIT(UCSRA_TXC));
}

/* --- receiver ------------------------------------------------------------ */

static void usart_rx_flush(usart_t *u)
{
	u->rx_fifo_len = 0;
	u->rx_shift_full = 0;
	u->rx_dor = 0;
}

/* The frame in the shift register is lost (DOR): the next frame to enter
 * the FIFO carries DOR ("frames lost between the last frame read and the
 * next one"). */
static void usart_rx_overrun(usart_t *u, avr_cycle_count_t cycle)
{
	trace_event(u->trace, cycle, "uart overrun %02X", u->rx_shift_byte);
	u->rx_dor = 1;
	u->rx_lost++;
}

/* A start bit on the wire. Silicon overruns here, not when the frame
 * ends: with two frames unread in UDR and a third complete in the shift
 * register, the new frame shifts in over that third (DOR). */
static void usart_rx_start_bit(usart_t *u, avr_cycle_count_t start)
{
	if (u->rx_fifo_len == 2 && u->rx_shift_full) {
		usart_rx_overrun(u, start);
		u->rx_shift_full = 0;
	}
}

static void usart_rx_deliver(usart_t *u, uint8_t byte, int fe)
{
	if (u->rx_fifo_len < 2) {
		u->rx_fifo[u->rx_fifo_len].data = byte;
		u->rx_fifo[u->rx_fifo_len].dor = (uint8_t)u->rx_dor;
		u->rx_dor = 0;
		u->rx_fifo[u->rx_fifo_len].fe = (uint8_t)fe;
		u->rx_fifo_len++;
	} else if (!u->rx_shift_full) {
		u->rx_shift_full = 1;
		u->rx_shift_byte = byte;
		u->rx_shift_fe = (uint8_t)fe;
	} else {
		/* Overrun: the frame waiting in the shifter is overwritten. */
		usart_rx_overrun(u, u->avr->cycle);
		u->rx_shift_byte = byte;
		u->rx_shift_fe = (uint8_t)fe;
	}
}

/* --- frames on the pins: the PC's on RXD, the board's on TXD ----------- */

static avr_cycle_count_t usart_wave_timer(avr_t *avr, avr_cycle_count_t when,
					  void *param)
{
	usart_wave_t *w = param;
	int level = sim_uart_frame_bit(w->byte, w->k);

	(void)avr;
	if (level != w->level) {
		w->level = level;
		w->pin(w->param, level, when);
	}
	while (++w->k <= 9) {
		if (sim_uart_frame_bit(w->byte, w->k) != level) {
			return w->start + (avr_cycle_count_t)w->k * w->bit;
		}
	}
	return 0;
}

/* Draw a frame on W's pin, its start bit from START (now or a few cycles
 * ago), BIT cycles a bit. */
static void usart_wave_frame(avr_t *avr, usart_wave_t *w, uint8_t byte,
			     avr_cycle_count_t start, uint32_t bit)
{
	avr_cycle_count_t next;

	if (!w->pin) {
		return;
	}
	avr_cycle_timer_cancel(avr, usart_wave_timer, w);
	w->start = start;
	w->bit = bit;
	w->byte = byte;
	w->k = 0;
	next = usart_wave_timer(avr, start, w);
	if (next) {
		avr_cycle_timer_register(avr, next > avr->cycle ? next - avr->cycle : 0,
					 usart_wave_timer, w);
	}
}

/* Cut off the frame being drawn: the pin goes idle (LEVEL 1) or is let go
 * (-1) at cycle NOW. */
static void usart_wave_stop(avr_t *avr, usart_wave_t *w, int level, avr_cycle_count_t now)
{
	if (!w->pin) {
		return;
	}
	avr_cycle_timer_cancel(avr, usart_wave_timer, w);
	if (level < 0 || w->level != level) {
		w->pin(w->param, level, now);
	}
	w->level = 1;
}

static void usart_rx_dec_emit(void *param, avr_cycle_count_t when,
			      avr_cycle_count_t t0, uint8_t byte, int fe)
{
	usart_t *u = param;

	if (usart_rxen(u) && t0 >= u->rxen_since) {
		trace_event(u->trace, when, fe ? "uart rx %02X fe" : "uart rx %02X", byte);
		usart_rx_deliver(u, byte, fe);
		usart_sync(u);
	}
	u->activity++;
}

static avr_cycle_count_t usart_rx_dec_timer(avr_t *avr, avr_cycle_count_t when,
					    void *param);

/* Run the board's receiver over the line up to now and plan its next run. */
static void usart_rx_dec_kick(usart_t *u)
{
	avr_t *avr = u->avr;
	avr_cycle_count_t next = sim_uart_dec_run(&u->rx_dec, &u->rx_line, usart_board_bit(u),
					      avr->cycle, usart_rx_dec_emit, u);

	if (u->rx_dec_armed) {
		avr_cycle_timer_cancel(avr, usart_rx_dec_timer, u);
	}
	u->rx_dec_armed = next != 0;
	if (next) {
		avr_cycle_timer_register(avr, next - avr->cycle, usart_rx_dec_timer, u);
	}
}

static avr_cycle_count_t usart_rx_dec_timer(avr_t *avr, avr_cycle_count_t when,
					    void *param)
{
	usart_t *u = param;
	avr_cycle_count_t next = sim_uart_dec_run(&u->rx_dec, &u->rx_line, usart_board_bit(u),
					      when, usart_rx_dec_emit, u);

	(void)avr;
	u->rx_dec_armed = next != 0;
	return next;
}

/*
 * The wire. One timer, usart_rx_timer, is due at the end of the byte on the
 * wire or, while the wire is idle, at the start of the next scheduled byte.
 * A scheduled byte owns the wire from its start; a host byte goes on the
 * idle wire only if it ends by the next scheduled start, else it waits.
 */
static void usart_rx_begin(usart_t *u, uint8_t byte, avr_cycle_count_t start,
			   avr_cycle_count_t end)
{
	if (usart_rxen(u)) {
		usart_rx_start_bit(u, start);
	}
	u->rx_wire_byte = byte;
	u->rx_wire_busy = 1;
	u->rx_wire_end = end;
	u->rx_wire_valid = usart_rxen(u);
	/* Fast path: the rates agree and the receiver is not inside a frame
	 * of its own, so it takes this byte whole at the end of its stop bit
	 * (exactly as before the line had rates). Otherwise the receiver
	 * decodes the waveform. */
	if (u->rx_dec_armed) {
		usart_rx_dec_kick(u);
	}
	u->rx_wire_fast = usart_board_bit(u) == u->host_bit && !u->rx_dec.busy;
	if (u->rx_wire_fast) {
		sim_uart_dec_skip_to(&u->rx_dec, end);
	}
	sim_uart_line_push(&u->rx_line, start, u->host_bit, byte, u->rx_wire_fast);
	usart_wave_frame(u->avr, &u->rxd, byte, start, u->host_bit);
	if (!u->rx_wire_fast) {
		usart_rx_dec_kick(u);
	}
}

/* Put the next byte on the idle wire at NOW. Returns the cycle the wire
 * timer is due next (that byte's end, or the next scheduled start), or 0
 * when there is nothing to send. */
static avr_cycle_count_t usart_rx_next(usart_t *u, avr_cycle_count_t now)
{
	const usart_inject_t *inj = u->inj_len ? &u->inj_q[u->inj_head] : NULL;
	avr_cycle_count_t bt = usart_host_byte_cycles(u);

	u->rx_wire_busy = 0;
	if (inj && inj->start <= now) {
		usart_rx_begin(u, inj->byte, inj->start, inj->start + inj->cycles);
		u->inj_head = (u->inj_head + 1) % USART_INJECT_QUEUE;
		u->inj_len--;
		return u->rx_wire_end;
	}
	if (u->host_len && (!inj || now + bt <= inj->start)) {
		uint8_t byte = u->host_q[u->host_head];

		u->host_head = (u->host_head + 1) % USART_HOST_QUEUE;
		u->host_len--;
		usart_rx_begin(u, byte, now, now + bt);
		return u->rx_wire_end;
	}
	return inj ? inj->start : 0;
}

static avr_cycle_count_t usart_rx_timer(avr_t *avr, avr_cycle_count_t when,
					void *param)
{
	usart_t *u = param;
	avr_cycle_count_t next;

	(void)avr;
	if (u->rx_wire_busy) {
		if (u->rx_wire_fast && u->rx_wire_valid &&
		    (usart_ucsrb(u) & BIT(UCSRB_RXEN))) {
			trace_event(u->trace, when, "uart rx %02X", u->rx_wire_byte);
			usart_rx_deliver(u, u->rx_wire_byte, 0);
			usart_sync(u);
		}
		u->activity++;
	}
	next = usart_rx_next(u, when);
	u->rx_timer_armed = next != 0;
	return next;
}

/* Something new to send: if the wire is idle, (re)plan its timer now. */
static void usart_rx_kick(usart_t *u)
{
	avr_t *avr = u->avr;
	avr_cycle_count_t next;

	if (u->rx_wire_busy) {
		return;		/* the timer at the byte's end takes it from there */
	}
	if (u->rx_timer_armed) {
		avr_cycle_timer_cancel(avr, usart_rx_timer, u);
	}
	next = usart_rx_next(u, avr->cycle);
	u->rx_timer_armed = next != 0;
	if (next) {
		avr_cycle_timer_register(avr, next - avr->cycle, usart_rx_timer, u);
	}
}

size_t usart_host_room(const usart_t *u)
{
	return USART_HOST_QUEUE - u->host_len;
}

void usart_host_send(usart_t *u, const uint8_t *buf, size_t n)
{
	for (size_t i = 0; i < n && u->host_len < USART_HOST_QUEUE; i++) {
		u->host_q[(u->host_head + u->host_len) % USART_HOST_QUEUE] = buf[i];
		u->host_len++;
		u->host_taken++;
	}
	usart_rx_kick(u);
}

avr_cycle_count_t usart_inject_free_at(const usart_t *u)
{
	avr_cycle_count_t t = u->avr->cycle;

	if (u->rx_wire_busy && u->rx_wire_end > t) {
		t = u->rx_wire_end;
	}
	if (u->inj_len && u->inj_end > t) {
		t = u->inj_end;
	}
	return t;
}

size_t usart_inject_room(const usart_t *u)
{
	return USART_INJECT_QUEUE - u->inj_len;
}

size_t usart_inject_pending(const usart_t *u)
{
	return u->inj_len;
}

avr_cycle_count_t usart_inject(usart_t *u, avr_cycle_count_t start,
			       const uint8_t *buf, size_t n)
{
	uint32_t bt = (uint32_t)usart_host_byte_cycles(u);

	if (n == 0 || n > usart_inject_room(u) || start < usart_inject_free_at(u)) {
		return 0;
	}
	for (size_t i = 0; i < n; i++) {
		usart_inject_t *e = &u->inj_q[(u->inj_head + u->inj_len) % USART_INJECT_QUEUE];

		e->start = start + i * bt;
		e->cycles = bt;
		e->byte = buf[i];
		u->inj_len++;
	}
	u->inj_end = start + n * bt;
	usart_rx_kick(u);
	return u->inj_end;
}

/* --- transmitter --------------------------------------------------------- */

static void usart_pc_emit(void *param, avr_cycle_count_t when,
			  avr_cycle_count_t t0, uint8_t byte, int fe)
{
	usart_t *u = param;

	(void)when;
	(void)t0;
	/* Linux hands the reader a character with a framing error as 0x00
	 * (IGNPAR and PARMRK off, as pyserial leaves them). */
	if (u->to_host) {
		u->to_host(u->to_host_param, fe ? 0 : byte);
	}
}

static avr_cycle_count_t usart_pc_dec_timer(avr_t *avr, avr_cycle_count_t when,
					    void *param)
{
	usart_t *u = param;
	avr_cycle_count_t next = sim_uart_dec_run(&u->pc_dec, &u->tx_line, u->host_bit,
					      when, usart_pc_emit, u);

	(void)avr;
	u->pc_dec_armed = next != 0;
	return next;
}

static void usart_pc_dec_kick(usart_t *u)
{
	avr_t *avr = u->avr;
	avr_cycle_count_t next = sim_uart_dec_run(&u->pc_dec, &u->tx_line, u->host_bit,
					      avr->cycle, usart_pc_emit, u);

	if (u->pc_dec_armed) {
		avr_cycle_timer_cancel(avr, usart_pc_dec_timer, u);
	}
	u->pc_dec_armed = next != 0;
	if (next) {
		avr_cycle_timer_register(avr, next - avr->cycle, usart_pc_dec_timer, u);
	}
}

/* The transmitter owns TXD while TXEN is on or a byte is still going out
 * (the datasheet lets pending transmissions complete); it idles high. */
static void usart_txd_update(usart_t *u, avr_cycle_count_t now)
{
	int own = (usart_ucsrb(u) & BIT(UCSRB_TXEN)) || u->tx_shift_busy;

	if (own == u->txd_owned || !u->txd.pin) {
		return;
	}
	u->txd_owned = own;
	if (own) {
		u->txd.level = 1;
		u->txd.pin(u->txd.param, 1, now);
	} else {
		usart_wave_stop(u->avr, &u->txd, -1, now);
	}
}

/* Move the buffer into the idle shifter: the start bit begins at WHEN. */
static int usart_tx_load(usart_t *u, avr_cycle_count_t when)
{
	if (u->tx_shift_busy || !u->tx_buf_full) {
		return 0;
	}
	u->tx_shift_byte = u->tx_buf;
	u->tx_shift_busy = 1;
	u->tx_buf_full = 0;
	u->ucsra |= BIT(UCSRA_UDRE);
	trace_event(u->trace, when, "uart tx %02X", u->tx_shift_byte);
	usart_wave_frame(u->avr, &u->txd, u->tx_shift_byte, when, usart_board_bit(u));
	/* As on the receive side: equal rates hand the PC the byte whole. */
	if (u->pc_dec_armed) {
		usart_pc_dec_kick(u);
	}
	u->tx_fast = usart_board_bit(u) == u->host_bit && !u->pc_dec.busy;
	if (u->tx_fast) {
		sim_uart_dec_skip_to(&u->pc_dec, when + usart_byte_cycles(u));
	}
	sim_uart_line_push(&u->tx_line, when, usart_board_bit(u), u->tx_shift_byte, u->tx_fast);
	if (!u->tx_fast) {
		usart_pc_dec_kick(u);
	}
	return 1;
}

static avr_cycle_count_t usart_tx_timer(avr_t *avr, avr_cycle_count_t when,
					void *param)
{
	usart_t *u = param;

	(void)avr;
	u->tx_shift_busy = 0;
	u->activity++;
	if (u->tx_fast && u->to_host) {
		u->to_host(u->to_host_param, u->tx_shift_byte);
	}
	/* A byte already in the buffer goes out even if TXEN was cleared
	 * meanwhile: the datasheet lets pending transmissions complete. */
	if (usart_tx_load(u, when)) {
		usart_sync(u);
		return when + usart_byte_cycles(u);
	}
	u->ucsra |= BIT(UCSRA_TXC);
	usart_txd_update(u, when);
	usart_sync(u);
	return 0;
}

static void usart_tx_kick(usart_t *u)
{
	if ((usart_ucsrb(u) & BIT(UCSRB_TXEN)) && usart_tx_load(u, u->avr->cycle)) {
		avr_cycle_timer_register(u->avr, usart_byte_cycles(u),
					 usart_tx_timer, u);
	}
}

/* --- registers ----------------------------------------------------------- */

static uint8_t usart_read_udr(avr_t *avr, avr_io_addr_t addr, void *param)
{
	usart_t *u = param;

	(void)avr;
	(void)addr;
	if (u->rx_fifo_len) {
		u->rx_last = u->rx_fifo[0].data;
		u->fe_read += u->rx_fifo[0].fe;
		u->rx_fifo[0] = u->rx_fifo[1];
		u->rx_fifo_len--;
		if (u->rx_shift_full) {
			u->rx_fifo[u->rx_fifo_len].data = u->rx_shift_byte;
			u->rx_fifo[u->rx_fifo_len].fe = u->rx_shift_fe;
			u->rx_fifo[u->rx_fifo_len].dor = (uint8_t)u->rx_dor;
			u->rx_fifo_len++;
			u->rx_shift_full = 0;
			u->rx_dor = 0;
		}
		usart_sync(u);
	}
	return u->rx_last;
}

static void usart_write_udr(avr_t *avr, avr_io_addr_t addr, uint8_t v,
			    void *param)
{
	usart_t *u = param;

	(void)avr;
	(void)addr;
	if (!(u->ucsra & BIT(UCSRA_UDRE))) {
		return;		/* silicon ignores a write to a full buffer */
	}
	u->tx_buf = v;
	u->tx_buf_full = 1;
	u->ucsra &= ~BIT(UCSRA_UDRE);
	usart_tx_kick(u);
	usart_sync(u);
}

static uint8_t usart_read_ucsra(avr_t *avr, avr_io_addr_t addr, void *param)
{
	(void)avr;
	(void)addr;
	return usart_ucsra(param);
}

static void usart_write_ucsra(avr_t *avr, avr_io_addr_t addr, uint8_t v,
			      void *param)
{
	usart_t *u = param;

	(void)avr;
	(void)addr;
	if (v & BIT(UCSRA_TXC)) {
		u->ucsra &= ~BIT(UCSRA_TXC);
	}
	u->ucsra = (u->ucsra & ~(BIT(UCSRA_U2X) | BIT(UCSRA_MPCM))) |
		   (v & (BIT(UCSRA_U2X) | BIT(UCSRA_MPCM)));
	usart_sync(u);
}

static void usart_write_ucsrb(avr_t *avr, avr_io_addr_t addr, uint8_t v,
			      void *param)
{
	usart_t *u = param;
	uint8_t old = avr->data[addr];

	v = (uint8_t)((v & ~BIT(UCSRB_RXB8)) | (old & BIT(UCSRB_RXB8)));
	avr->data[addr] = v;
	if ((old & BIT(UCSRB_RXEN)) && !(v & BIT(UCSRB_RXEN))) {
		usart_rx_flush(u);
	}
	if (!(old & BIT(UCSRB_RXEN)) && (v & BIT(UCSRB_RXEN))) {
		/* The receiver starts looking for a start bit from now on. */
		u->rxen_since = avr->cycle;
		sim_uart_dec_skip_to(&u->rx_dec, avr->cycle);
		trace_event(u->trace, avr->cycle, "line rxen %u%s", (unsigned)u->ubrr,
			    (u->ucsra & BIT(UCSRA_U2X)) ? " u2x" : "");
	}
	usart_txd_update(u, avr->cycle);
	if (v & BIT(UCSRB_TXEN)) {
		usart_tx_kick(u);
	}
	usart_sync(u);
}

static void usart_write_ubrrl(avr_t *avr, avr_io_addr_t addr, uint8_t v,
			      void *param)
{
	usart_t *u = param;

	avr->data[addr] = v;
	u->ubrr = (uint16_t)((u->ubrr & 0x0f00) | v);
}

static void usart_set_ubrrh(usart_t *u, uint8_t v)
{
	u->ubrr = (uint16_t)((u->ubrr & 0x00ff) | ((v & 0x0f) << 8));
}

/* ATmega128: UBRRH and UCSRC have addresses of their own. */
static void usart_write_ubrrh(avr_t *avr, avr_io_addr_t addr, uint8_t v,
			      void *param)
{
	avr->data[addr] = v & 0x0f;
	usart_set_ubrrh(param, v);
}

static void usart_write_ucsrc(avr_t *avr, avr_io_addr_t addr, uint8_t v,
			      void *param)
{
	usart_t *u = param;

	u->ucsrc = v & 0x7f;
	avr->data[addr] = u->ucsrc;
}

/* ATmega32: one address, URSEL (bit 7) picks UCSRC on write. On read, the
 * first access returns UBRRH and one in the very next cycle UCSRC. */
static void usart_write_shared(avr_t *avr, avr_io_addr_t addr, uint8_t v,
			       void *param)
{
	usart_t *u = param;

	(void)avr;
	(void)addr;
	if (v & BIT(UCSRC_URSEL)) {
		u->ucsrc = v & 0x7f;
	} else {
		usart_set_ubrrh(u, v);
	}
}

static uint8_t usart_read_shared(avr_t *avr, avr_io_addr_t addr, void *param)
{
	usart_t *u = param;
	uint8_t v;

	(void)addr;
	if (avr->cycle == u->ubrrh_read_cycle + 1) {
		v = (uint8_t)(BIT(UCSRC_URSEL) | u->ucsrc);
	} else {
		v = (uint8_t)(u->ubrr >> 8);
	}
	u->ubrrh_read_cycle = avr->cycle;
	return v;
}

static void usart_irq_running(struct avr_irq_t *irq, uint32_t value,
			      void *param)
{
	usart_t *u = param;

	/* TXC is the one flag the hardware clears on entering its ISR. */
	if (value && irq == &u->vect_txc.irq[AVR_INT_IRQ_RUNNING]) {
		u->ucsra &= ~BIT(UCSRA_TXC);
	}
	usart_sync(u);
}

/* --- reset --------------------------------------------------------------- */

static void usart_reset(avr_io_t *io)
{
	usart_t *u = (usart_t *)io;
	avr_t *avr = u->avr;
	const sim_mcu_usart_t *r = u->regs;

	/* avr_reset has wiped the cycle timers: the byte on the wire is lost
	 * in both directions; the host queue and the scheduled bytes keep
	 * flowing (into a receiver that is off until the firmware enables it). */
	u->ucsra = BIT(UCSRA_UDRE);
	u->ucsrc = BIT(UCSRC_UCSZ1) | BIT(UCSRC_UCSZ0);
	u->ubrr = 0;
	usart_rx_flush(u);
	u->rx_wire_busy = 0;
	avr_cycle_timer_cancel(avr, usart_rx_timer, u);
	u->rx_timer_armed = 0;
	u->rx_dec_armed = 0;
	u->pc_dec_armed = 0;
	memset(&u->rx_dec, 0, sizeof(u->rx_dec));
	memset(&u->pc_dec, 0, sizeof(u->pc_dec));
	u->rx_dec.cursor = u->pc_dec.cursor = avr->cycle;
	u->rxen_since = avr->cycle;
	usart_wave_stop(avr, &u->rxd, 1, avr->cycle);	/* the frame being drawn is cut off */
	u->tx_buf_full = 0;
	u->tx_shift_busy = 0;
	avr->data[r->ucsrb] = 0;
	usart_txd_update(u, avr->cycle);
	avr->data[r->ubrrl] = 0;
	avr->data[r->ubrrh] = 0;
	if (!sim_mcu_usart_shared_ucsrc(r)) {
		avr->data[r->ucsrc] = u->ucsrc;
	}
	usart_sync(u);
	usart_rx_kick(u);
}

void usart_init(usart_t *u, avr_t *avr, const sim_mcu_usart_t *regs,
		trace_t *trace, usart_to_host_t to_host, void *param)
{
	memset(u, 0, sizeof(*u));
	u->avr = avr;
	u->regs = regs;
	u->trace = trace;
	u->to_host = to_host;
	u->to_host_param = param;
	u->io.kind = "orfa-usart";
	u->rxd.level = u->txd.level = 1;
	u->host_baud = 115200;
	u->host_bit = 64;
	u->io.reset = usart_reset;

	u->vect_rxc = (avr_int_vector_t) {
		.vector = regs->vect_rxc,
		.enable = AVR_IO_REGBIT(regs->ucsrb, UCSRB_RXCIE),
		.raised = AVR_IO_REGBIT(regs->ucsra, UCSRA_RXC),
		.raise_sticky = 1,
	};
	u->vect_udre = (avr_int_vector_t) {
		.vector = regs->vect_udre,
		.enable = AVR_IO_REGBIT(regs->ucsrb, UCSRB_UDRIE),
		.raised = AVR_IO_REGBIT(regs->ucsra, UCSRA_UDRE),
		.raise_sticky = 1,
	};
	u->vect_txc = (avr_int_vector_t) {
		.vector = regs->vect_txc,
		.enable = AVR_IO_REGBIT(regs->ucsrb, UCSRB_TXCIE),
		.raised = AVR_IO_REGBIT(regs->ucsra, UCSRA_TXC),
	};
	avr_register_vector(avr, &u->vect_rxc);
	avr_register_vector(avr, &u->vect_udre);
	avr_register_vector(avr, &u->vect_txc);
	avr_irq_register_notify(&u->vect_rxc.irq[AVR_INT_IRQ_RUNNING],
				usart_irq_running, u);
	avr_irq_register_notify(&u->vect_udre.irq[AVR_INT_IRQ_RUNNING],
				usart_irq_running, u);
	avr_irq_register_notify(&u->vect_txc.irq[AVR_INT_IRQ_RUNNING],
				usart_irq_running, u);

	io_hook_take(avr, regs->udr, usart_read_udr, usart_write_udr, u);
	io_hook_take(avr, regs->ucsra, usart_read_ucsra, usart_write_ucsra, u);
	io_hook_take(avr, regs->ucsrb, NULL, usart_write_ucsrb, u);
	io_hook_take(avr, regs->ubrrl, NULL, usart_write_ubrrl, u);
	if (sim_mcu_usart_shared_ucsrc(regs)) {
		io_hook_take(avr, regs->ubrrh, usart_read_shared,
			   usart_write_shared, u);
	} else {
		io_hook_take(avr, regs->ubrrh, NULL, usart_write_ubrrh, u);
		io_hook_take(avr, regs->ucsrc, NULL, usart_write_ucsrc, u);
	}

	io_hook_register_last(avr, &u->io);
	usart_reset(&u->io);
}

void usart_set_host_baud(usart_t *u, uint32_t baud)
{
	uint32_t f = u->avr->frequency;	/* board.h's clock, set before usart_init */

	if (baud == 0 || baud == u->host_baud) {
		return;
	}
	u->host_baud = baud;
	u->host_bit = (f + baud / 2) / baud;
	if (u->host_bit == 0) {
		u->host_bit = 1;
	}
}

void usart_set_pin(usart_t *u, usart_pin_t pin, void *param)
{
	u->rxd.pin = pin;
	u->rxd.param = param;
	u->rxd.level = 1;
	pin(param, 1, u->avr->cycle);
}

void usart_set_tx_pin(usart_t *u, usart_pin_t pin, void *param)
{
	u->txd.pin = pin;
	u->txd.param = param;
	u->txd.level = 1;
	u->txd_owned = 0;
	pin(param, -1, u->avr->cycle);
	usart_txd_update(u, u->avr->cycle);
}
