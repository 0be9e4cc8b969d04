/* sim_uart_line.c: see sim_uart_line.h. */
#include "periph/sim_uart_line.h"

void sim_uart_line_reset(sim_uart_line_t *l)
{
	l->head = l->len = 0;
}

void sim_uart_line_push(sim_uart_line_t *l, avr_cycle_count_t start, uint32_t bit,
		    uint8_t byte, int skip)
{
	sim_uart_frame_t *f;

	if (l->len == UART_LINE_FRAMES) {
		l->head = (l->head + 1) % UART_LINE_FRAMES;
		l->len--;
	}
	f = &l->f[(l->head + l->len) % UART_LINE_FRAMES];
	f->start = start;
	f->bit = bit;
	f->byte = byte;
	f->skip = (uint8_t)skip;
	l->len++;
}

static const sim_uart_frame_t *sim_uart_line_at(const sim_uart_line_t *l, unsigned i)
{
	return &l->f[(l->head + i) % UART_LINE_FRAMES];
}

int sim_uart_line_level(const sim_uart_line_t *l, avr_cycle_count_t t)
{
	for (unsigned i = l->len; i-- > 0;) {
		const sim_uart_frame_t *f = sim_uart_line_at(l, i);

		if (f->start <= t) {
			avr_cycle_count_t k = (t - f->start) / f->bit;

			return k >= 10 ? 1 : sim_uart_frame_bit(f->byte, (int)k);
		}
	}
	return 1;
}

/* The first falling edge at or after T, 0 when the line has none. */
static avr_cycle_count_t sim_uart_line_next_fall(const sim_uart_line_t *l, avr_cycle_count_t t)
{
	unsigned i = l->len;

	/* back to the frame that holds T, then forward */
	while (i > 0 && sim_uart_line_at(l, i - 1)->start + 10ull * sim_uart_line_at(l, i - 1)->bit > t) {
		i--;
	}
	for (; i < l->len; i++) {
		const sim_uart_frame_t *f = sim_uart_line_at(l, i);

		if (f->skip) {
			continue;
		}
		for (int k = 0; k <= 8; k++) {
			avr_cycle_count_t e = f->start + (avr_cycle_count_t)k * f->bit;

			if (e >= t && !sim_uart_frame_bit(f->byte, k) &&
			    (k == 0 || sim_uart_frame_bit(f->byte, k - 1))) {
				return e;
			}
		}
	}
	return 0;
}

/* Majority of the samples 8, 9, 10 (of 16) of the bit centred at C. */
static int sim_uart_dec_sample(const sim_uart_line_t *l, avr_cycle_count_t c, uint32_t bit)
{
	uint32_t d = bit / 16 ? bit / 16 : 1;

	return sim_uart_line_level(l, c - d) + sim_uart_line_level(l, c) +
	       sim_uart_line_level(l, c + d) >= 2;
}

static avr_cycle_count_t sim_uart_dec_last(avr_cycle_count_t t0, uint32_t bit)
{
	uint32_t d = bit / 16 ? bit / 16 : 1;

	return t0 + 9ull * bit + bit / 2 + d;
}

avr_cycle_count_t sim_uart_dec_run(sim_uart_dec_t *d, const sim_uart_line_t *l, uint32_t bit,
			       avr_cycle_count_t until, sim_uart_dec_emit_t emit,
			       void *param)
{
	for (;;) {
		if (!d->busy) {
			avr_cycle_count_t e = sim_uart_line_next_fall(l, d->cursor);

			if (!e) {
				return 0;
			}
			if (e > until) {
				return sim_uart_dec_last(e, bit);
			}
			d->busy = 1;
			d->t0 = e;
			d->bit = bit;
		}
		uint32_t b = d->bit;
		avr_cycle_count_t last = sim_uart_dec_last(d->t0, b);

		if (last > until) {
			return last;
		}
		d->busy = 0;
		if (sim_uart_dec_sample(l, d->t0 + b / 2, b)) {
			d->cursor = d->t0 + 1;		/* false start */
			continue;
		}
		uint8_t byte = 0;

		for (int i = 0; i < 8; i++) {
			byte |= (uint8_t)(sim_uart_dec_sample(l, d->t0 + (2ull * i + 3) * b / 2, b) << i);
		}
		int stop = sim_uart_dec_sample(l, d->t0 + 19ull * b / 2, b);

		d->cursor = d->t0 + 19ull * b / 2;
		emit(param, last, d->t0, byte, !stop);
	}
}
