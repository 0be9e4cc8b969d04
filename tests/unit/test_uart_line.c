/*
 * The simulator's serial line (sim/periph/sim_uart_line.c): frames at a sender's bit
 * time decoded by a receiver at its own, the way the AVR's USART samples
 * (majority of three at each bit's middle, FE on a low stop bit).
 */
#include <stdio.h>
#include <string.h>

#include "periph/sim_uart_line.h"

#include "check.h"

typedef struct {
	int n;
	uint8_t byte[64];
	int fe[64];
	avr_cycle_count_t when[64], t0[64];
} got_t;

static void emit(void *param, avr_cycle_count_t when, avr_cycle_count_t t0,
		 uint8_t byte, int fe)
{
	got_t *g = param;

	if (g->n < 64) {
		g->byte[g->n] = byte;
		g->fe[g->n] = fe;
		g->when[g->n] = when;
		g->t0[g->n] = t0;
		g->n++;
	}
}

static sim_uart_line_t line;

/* Frames back to back from START at the sender's BIT; decoded at RX_BIT. */
static void decode(const uint8_t *bytes, int n, uint32_t bit, uint32_t rx_bit,
		   avr_cycle_count_t step, got_t *g)
{
	sim_uart_dec_t d = { .cursor = 0 };
	avr_cycle_count_t start = 1000, end;

	memset(g, 0, sizeof(*g));
	sim_uart_line_reset(&line);
	for (int i = 0; i < n; i++) {
		sim_uart_line_push(&line, start + (avr_cycle_count_t)i * 10 * bit, bit, bytes[i], 0);
	}
	end = start + (avr_cycle_count_t)(n + 20) * 10 * (bit > rx_bit ? bit : rx_bit);
	/* the same result whether run in one go or in small steps */
	for (avr_cycle_count_t t = step ? step : end; ; t += step ? step : end) {
		sim_uart_dec_run(&d, &line, rx_bit, t < end ? t : end, emit, g);
		if (t >= end) {
			break;
		}
	}
}

static void test_equal_rates_every_byte(void)
{
	static const uint32_t bits[] = { 3072, 1536, 768, 512, 384, 256, 192, 128, 96, 64 };
	uint8_t all[256];
	got_t g;

	for (int i = 0; i < 256; i++) {
		all[i] = (uint8_t)i;
	}
	for (unsigned r = 0; r < sizeof(bits) / sizeof(bits[0]); r++) {
		for (int chunk = 0; chunk < 256; chunk += 64) {
			decode(all + chunk, 64, bits[r], bits[r], 0, &g);
			CHECK(g.n == 64, "bit %u: %d frames", bits[r], g.n);
			for (int i = 0; i < g.n; i++) {
				CHECK(g.byte[i] == chunk + i && !g.fe[i], "bit %u: %02X fe %d for %02X",
				      bits[r], g.byte[i], g.fe[i], chunk + i);
			}
		}
	}
	/* the frame enters the buffer at the stop bit's last sample */
	decode((const uint8_t *)"\r", 1, 64, 64, 0, &g);
	CHECK(g.n == 1 && g.t0[0] == 1000 && g.when[0] == 1000 + 9 * 64 + 32 + 4,
	      "when %llu", (unsigned long long)g.when[0]);
}

static void test_small_rate_error_still_decodes(void)
{
	got_t g;
	const uint8_t msg[] = "S AA 00 00 S AB 01 P\r";

	/* 3 % slow and fast receivers: still the bytes (silicon tolerates ~4 %) */
	decode(msg, (int)sizeof(msg) - 1, 64, 66, 0, &g);
	CHECK(g.n == (int)sizeof(msg) - 1 && !memcmp(g.byte, msg, sizeof(msg) - 1), "slow rx");
	decode(msg, (int)sizeof(msg) - 1, 66, 64, 0, &g);
	CHECK(g.n == (int)sizeof(msg) - 1 && !memcmp(g.byte, msg, sizeof(msg) - 1), "fast rx");
}

static void test_pc_at_9600_board_at_115200(void)
{
	got_t g;

	/* 'V' at 9600: its start bit alone is 12 of the board's bits: 00, FE */
	decode((const uint8_t *)"V", 1, 768, 64, 0, &g);
	CHECK(g.n >= 1 && g.byte[0] == 0x00 && g.fe[0], "%d frames, %02X fe %d",
	      g.n, g.byte[0], g.fe[0]);
	for (int i = 0; i < g.n; i++) {
		CHECK(g.byte[i] != 'V', "a V came through");
	}
}

static void test_pc_at_115200_board_at_9600(void)
{
	got_t g;
	const uint8_t cr8[] = "\r\r\r\r\r\r\r\r";

	decode(cr8, 8, 64, 768, 0, &g);
	CHECK(g.n >= 1, "nothing decoded");
	for (int i = 0; i < g.n; i++) {
		CHECK(g.byte[i] != '\r', "a CR came through");
	}
}

static void test_false_start(void)
{
	got_t g;

	/* a 4-cycle low glitch (a start bit at a bit time of 4, data all 1) */
	decode((const uint8_t *)"\xff", 1, 4, 64, 0, &g);
	CHECK(g.n == 0, "%d frames from a glitch", g.n);
}

static void test_stepwise_equals_at_once(void)
{
	got_t a, b;
	const uint8_t msg[] = "V\rS 10 20 P\r\xff\x00\x55";

	decode(msg, (int)sizeof(msg) - 1, 96, 128, 0, &a);
	decode(msg, (int)sizeof(msg) - 1, 96, 128, 37, &b);
	CHECK(a.n == b.n && !memcmp(a.byte, b.byte, (size_t)a.n) &&
	      !memcmp(a.fe, b.fe, sizeof(int) * (size_t)a.n) &&
	      !memcmp(a.when, b.when, sizeof(a.when[0]) * (size_t)a.n), "stepwise differs");
}

int main(void)
{
	test_equal_rates_every_byte();
	test_small_rate_error_still_decodes();
	test_pc_at_9600_board_at_115200();
	test_pc_at_115200_board_at_9600();
	test_false_start();
	test_stepwise_equals_at_once();
	printf("uart line: %d passed, %d failed\n", checks - failures, failures);
	return failures != 0;
}
