/*
 * Unit tests of the serial gateway (parser + executor) and the register map,
 * compiled for the host with fakes of the bus and a test driver.
 * Prints "N passed, N failed".
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fakes.h"
#include "firmware/sys.h"
#include "firmware/twi_rate.h"
#include "serialgate/sg_exec.h"
#include "serialgate/sg_parse.h"
#include "serialgate/sg_rx.h"

static int passed, failed;
static sg_parser_t parser;

static void check(int ok, const char *what, const char *detail)
{
	if (ok) {
		passed++;
	} else {
		failed++;
		printf("FAIL %s %s\n", what, detail ? detail : "");
	}
}

/* A fresh board: reset state, then feed `in`. */
static void boot(void)
{
	fakes_reset();
	sg_rx_init();
	regmap_init();
	sg_parse_init(&parser);
	sg_exec_init();
}

static void feed(const char *in, size_t n)
{
	for (size_t i = 0; i < n; i++) {
		sg_event_t ev = sg_parse_char(&parser, (uint8_t)in[i]);
		if (ev == SG_REQUEST) {
			sg_exec(&parser);
		} else if (ev == SG_LOST) {
			sg_exec_lost(&parser);
		}
	}
}

static void escape(char *dst, size_t cap, const char *s)
{
	size_t k = 0;
	for (; *s && k + 5 < cap; s++) {
		if (*s == '\r') {
			k += (size_t)snprintf(dst + k, cap - k, "\\r");
		} else if (*s == '\n') {
			k += (size_t)snprintf(dst + k, cap - k, "\\n");
		} else {
			dst[k++] = *s;
		}
	}
	dst[k] = 0;
}

/* Feeds `in` (on the state left by earlier calls) and compares the replies
 * and the bus traffic. bus == NULL: don't care. */
static void expect_n(const char *in, size_t n, const char *reply, const char *bus)
{
	out_len = 0;
	out_buf[0] = 0;
	bus_log[0] = 0;
	feed(in, n);
	char a[600], b[600], c[900];
	escape(a, sizeof a, in);
	escape(b, sizeof b, out_buf);
	escape(c, sizeof c, reply ? reply : "");
	char detail[8192];
	if (reply) {
		snprintf(detail, sizeof detail, "in=\"%s\" got=\"%s\" want=\"%s\"", a, b, c);
		check(strcmp(out_buf, reply) == 0, "reply", detail);
	}
	if (bus) {
		snprintf(detail, sizeof detail, "in=\"%s\" bus=\"%s\" want=\"%s\"", a, bus_log, bus);
		check(strcmp(bus_log, bus) == 0, "bus", detail);
	}
}

static void expect(const char *in, const char *reply, const char *bus)
{
	expect_n(in, strlen(in), reply, bus);
}

static void test_simple_commands(void)
{
	boot();
	expect("V\r", "V1.1\r\n", "");
	expect("v\n", "V1.1\r\n", "");
	expect("V\r\n", "V1.1\r\n", "");
	expect("  V  \r", "V1.1\r\n", "");
	expect("\r\n\r\r\r\r\r\r\r\r", "", "");
	expect("# a comment S A0 00 P\r", "", "");
	expect("     \r", "", "");
	expect("  # not a comment\r", "ERROR 02\r\n", "");
	expect("Q\r", "ERROR 02\r\n", "");
	expect("P\r", "ERROR 02\r\n", "");
	expect("1\r", "ERROR 02\r\n", "");
	expect("\tV\r", "ERROR 02\r\n", "");
	expect("V1\r", "ERROR 04\r\n", "");
	expect("V V\r", "ERROR 04\r\n", "");
	expect("X\r", "X\r\n", "X ");
	expect("x\r", "X\r\n", "X ");
	expect("X X\r", "ERROR 04\r\n", "");
}

static void test_local_address(void)
{
	boot();
	expect("L\r", "LAA\r\n", "");
	expect("L21\r", "L20\r\n", "");
	expect("L\r", "L20\r\n", "");
	expect("l ab\r", "LAA\r\n", "");
	expect("L00\r", "ERROR 04\r\n", "");
	expect("L01\r", "ERROR 04\r\n", "");
	expect("LA\r", "ERROR 03\r\n", "");
	expect("L A A\r", "ERROR 03\r\n", "");
	expect("LZZ\r", "ERROR 03\r\n", "");
	expect("LAA BB\r", "ERROR 04\r\n", "");
	expect("LAAB\r", "ERROR 04\r\n", "");
	expect("L\r", "LAA\r\n", "");
	/* The local address moves: requests to the old one go to the bus. */
	expect("L A0\r", "LA0\r\n", "");
	expect("S A0 00 S A1 01 P\r", "SWASR03P\r\n", "");
	expect("S AA P\r", "ERROR 06\r\n", "S AA- P ");
}

static void test_clock(void)
{
	boot();
	expect("C\r", "C0063\r\n", "");
	expect("C0064\r", "C0063\r\n", "");
	expect("C0190\r", "C0170\r\n", "");
	expect("C\r", "C0170\r\n", "");
	expect("CFFFF\r", "C01CC\r\n", "");
	expect("c 00 0a\r", "C0009\r\n", "");
	expect("C0001\r", "C0000\r\n", "");
	expect("C0000\r", "ERROR 04\r\n", "");
	expect("C64\r", "ERROR 04\r\n", "");
	expect("C006\r", "ERROR 03\r\n", "");
	expect("C006400\r", "ERROR 04\r\n", "");
	expect("C00 64 1\r", "ERROR 04\r\n", "");
	expect("C0Z\r", "ERROR 03\r\n", "");
}

static void test_rates(void)
{
	/* SCL = F_CPU / (16 + 2 TWBR 4^TWPS), fastest not above. */
	struct { uint16_t khz; uint8_t twbr, twps; uint16_t got; } t[] = {
		{ 100, 29, 0, 99 }, { 400, 2, 0, 368 }, { 368, 3, 0, 335 },
		{ 369, 2, 0, 368 }, { 460, 1, 0, 409 }, { 461, 0, 0, 460 },
		{ 50, 66, 0, 49 }, { 14, 64, 1, 13 }, { 13, 69, 1, 12 },
		{ 1, 230, 2, 0 }, { 0xFFFF, 0, 0, 460 },
	};
	for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
		twi_rate_t r = twi_rate_for_khz(F_CPU, t[i].khz);
		char d[120];
		snprintf(d, sizeof d, "khz=%u twbr=%u twps=%u got=%u", t[i].khz, r.twbr, r.twps, r.khz);
		check(r.twbr == t[i].twbr && r.twps == t[i].twps && r.khz == t[i].got, "rate", d);
		/* never above the rate asked */
		check(F_CPU / r.period <= t[i].khz * 1000UL || t[i].khz == 0, "rate<=asked", d);
	}
	/* Every rate from 1 to 1000 kHz against a search of all TWBR/TWPS:
	 * the shortest period whose rate is not above the one asked (a
	 * prescaler only when TWBR alone cannot reach it). */
	int bad = 0;
	for (uint32_t khz = 1; khz <= 1000 && !bad; khz++) {
		uint32_t best = 0;
		for (uint32_t ps = 0; ps < 4 && !best; ps++) {
			for (uint32_t twbr = 0; twbr < 256; twbr++) {
				uint32_t period = 16 + 2 * twbr * (1u << (2 * ps));
				if (F_CPU <= khz * 1000UL * period) {  /* rate <= asked */
					best = period;
					break;
				}
			}
		}
		if (!best) {
			best = 16 + 2 * 255 * 64;
		}
		twi_rate_t r = twi_rate_for_khz(F_CPU, (uint16_t)khz);
		if (r.period != best || r.khz != F_CPU / (best * 1000UL)) {
			char d[120];
			snprintf(d, sizeof d, "khz=%u period=%lu want %lu", (unsigned)khz,
				 (unsigned long)r.period, (unsigned long)best);
			check(0, "rate search", d);
			bad = 1;
		}
	}
	check(!bad, "rates 1..1000 kHz", NULL);
}

static void test_i2c(void)
{
	boot();
	expect("S A0 00 11 22 P\r", "SWAAAP\r\n", "S A0+ W00+ W11+ W22+ P ");
	check(eeprom[0] == 0x11 && eeprom[1] == 0x22, "eeprom written", NULL);
	expect("S A0 00 S A1 02 P\r", "SWASR1122P\r\n", "S A0+ W00+ S A1+ R11+ R22- P ");
	expect("sa000sa102p\r", "SWASR1122P\r\n", NULL);
	expect("S A0 P\r", "SWP\r\n", "S A0+ P ");
	expect("S A1 01 P\r", "SRFFP\r\n", NULL);  /* address counter went on to 2 */
	expect("S A2 P\r", "ERROR 06\r\n", "S A2- P ");
	expect("S A2 00 S A1 01 P\r", "ERROR 06\r\n", "S A2- P ");
	expect("S 50 01 02 P\r", "ERROR 07\r\n", "S 50+ W01- P ");
	expect("S 60 01 P\r", "ERROR 06\r\n", "S 60! P ");
	/* every byte taken but no STOP made: the frame is dropped by its
	 * slave, so the request failed (docs/protocol.md, "Abandoned frames") */
	expect("S 62 01 02 P\r", "ERROR 07\r\n", "S 62+ W01+ W02+ P! ");
	expect("S 62 P\r", "ERROR 07\r\n", "S 62+ P! ");
	expect("S A0 10 S A1 04 P\r", "SWASRFFFFFFFFP\r\n", NULL);
	/* execution error: only the error, and STOP after the earlier frames */
	expect("S A0 05 77 S A2 P\r", "ERROR 06\r\n", "S A0+ W05+ W77+ S A2- P ");
	check(eeprom[5] == 0x77, "earlier frame took effect", NULL);
}

static void test_i2c_parse_errors(void)
{
	boot();
	expect("S 10 20\r", "ERROR 05\r\n", "");
	expect("S\r", "ERROR 05\r\n", "");
	expect("S A1 01\r", "ERROR 05\r\n", "");
	expect("S A0 00 S\r", "ERROR 05\r\n", "");
	expect("S P\r", "ERROR 03\r\n", "");
	expect("S S\r", "ERROR 03\r\n", "");
	expect("S 1 P\r", "ERROR 03\r\n", "");
	expect("S 1 0 P\r", "ERROR 03\r\n", "");
	expect("S 1G P\r", "ERROR 03\r\n", "");
	expect("S 10 2\r", "ERROR 03\r\n", "");
	expect("S A0 00 Q P\r", "ERROR 03\r\n", "");
	expect("S A1 01 Q\r", "ERROR 03\r\n", "");
	expect("S A1 P\r", "ERROR 04\r\n", "");
	expect("S A1 S A1 01 P\r", "ERROR 04\r\n", "");
	expect("S A1 00 P\r", "ERROR 04\r\n", "");
	expect("S A1 01 02 P\r", "ERROR 04\r\n", "");
	expect("S A0 00 P Q\r", "ERROR 04\r\n", "");
	expect("S A0 00 P 1\r", "ERROR 04\r\n", "");
	expect("S A0 00 P P\r", "ERROR 04\r\n", "");
	expect("S A0 00 P  \r", "SWAP\r\n", NULL);
	/* the first error decides */
	expect("S A1 00 G\r", "ERROR 04\r\n", "");
	expect("S 1G 00\r", "ERROR 03\r\n", "");
	/* nothing of an erroneous request runs */
	expect("S A0 00 55 S A1 0G P\r", "ERROR 03\r\n", "");
	check(eeprom[0] == 0xFF, "erroneous request left the EEPROM alone", NULL);
	/* and the next line is parsed normally */
	expect("S A0 00 55 P garbage\rV\r", "ERROR 04\r\nV1.1\r\n", "");
}

static void test_limits(void)
{
	boot();
	/* 128 characters: "S A0 00" + 40 data bytes " 00" = 7 + 120 = 127, + "P" */
	char line[400];
	strcpy(line, "S A0 00");
	for (int i = 0; i < 40; i++) {
		strcat(line, " 5A");
	}
	strcat(line, "P");
	check(strlen(line) == 128, "line is 128", NULL);
	strcat(line, "\r");
	char want[200] = "SW";
	for (int i = 0; i < 41; i++) {
		strcat(want, "A");
	}
	strcat(want, "P\r\n");
	expect(line, want, NULL);
	/* 129 characters: refused, nothing on the bus */
	strcpy(line, " S A0 00");
	for (int i = 0; i < 40; i++) {
		strcat(line, " 5A");
	}
	strcat(line, "P\r");
	check(strlen(line) == 130, "line is 129", NULL);
	fakes_reset();
	expect(line, "ERROR 04\r\n", "");
	check(eeprom[0] == 0xFF, "129-character request did nothing", NULL);
	/* a 129-character comment is still a comment */
	memset(line, 'c', 200);
	line[0] = '#';
	line[200] = '\r';
	line[201] = 0;
	expect(line, "", "");
	/* replies: SR + 2*62 + P = 127 accepted, 63 bytes refused */
	expect("S A1 3E P\r", NULL, NULL);
	check(out_len == 127 + 2, "127-character reply", out_buf);
	expect("S A1 3F P\r", "ERROR 04\r\n", "");
	expect("S A1 FF P\r", "ERROR 04\r\n", "");
	expect("S AA 00 01 S AB 3C P\r", NULL, NULL);
	check(out_len == 127 + 2, "10 introspection records fill the reply", out_buf);
	expect("S AA 00 01 S AB 3D P\r", "ERROR 04\r\n", "");
	/* a long line of spaces before V is over the limit */
	memset(line, ' ', 128);
	strcpy(line + 128, "V\r");
	expect(line, "ERROR 04\r\n", "");
	memset(line, ' ', 127);
	strcpy(line + 127, "V\r");
	expect(line, "V1.1\r\n", "");
	/* a line of nothing but spaces is empty however long: no reply */
	memset(line, ' ', 129);
	strcpy(line + 129, "\r");
	expect(line, "", "");
	memset(line, ' ', 300);
	strcpy(line + 300, "\rV\r");
	expect(line, "V1.1\r\n", "");
	memset(line, ' ', 300);
	strcpy(line + 300, "V\r");
	expect(line, "ERROR 04\r\n", "");
}

/* The sys driver (registers 0x05 RESET, 0x06 FAILSAFE here): reset causes
 * kept over resets, the failsafe's timing on a fake clock. */
static void test_sys(void)
{
	/* power-on: fresh, whatever SRAM held */
	sys_boot(0x01);
	boot();
	expect("S AA 05 S AB 01 P\r", "SWASR01P\r\n", "");
	/* a watchdog reset and an external one before the host clears: both */
	sys_boot(0x08);
	sys_boot(0x02);
	boot();
	expect("S AA 05 S AB 01 P\r", "SWASR0BP\r\n", "");
	/* writing clears the bits set in the byte */
	expect("S AA 05 08 P\r", "SWAAP\r\n", "");
	expect("S AA 05 S AB 01 P\r", "SWASR03P\r\n", "");
	expect("S AA 05 FF P\r", "SWAAP\r\n", "");
	expect("S AA 05 S AB 01 P\r", "SWASR00P\r\n", "");
	/* a later power-on forgets what came before */
	sys_boot(0x08);
	sys_boot(0x01);
	expect("S AA 05 S AB 01 P\r", "SWASR01P\r\n", "");
	/* one byte only */
	expect("S AA 05 01 02 P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR01P\r\n", "");
	expect("S AA 05 P\r", "SWAP\r\n", "");

	/* FAILSAFE: off after reset; two bytes; up to 18000 ms */
	expect("S AA 06 S AB 02 P\r", "SWASR0000P\r\n", "");
	expect("S AA 06 00 P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR01P\r\n", "");
	expect("S AA 06 00 64 00 P\r", "ERROR 07\r\n", "");
	expect("S AA 06 46 51 P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR02P\r\n", "");
	expect("S AA 06 S AB 02 P\r", "SWASR0000P\r\n", "");
	expect("S AA 06 46 50 P\r", "SWAAAP\r\n", "");
	expect("S AA 06 S AB 02 P\r", "SWASR4650P\r\n", "");

	/* 100 ms = 360 ticks, one more for the tick the request came in: trips
	 * at 361 quiet ticks, once */
	fake_clock = 65000;  /* across the clock's wrap */
	fake_safe_calls = 0;
	expect("S AA 06 00 64 P\r", "SWAAAP\r\n", "");
	fake_clock = (uint16_t)(65000 + 360);
	sys_poll();
	check(fake_safe_calls == 0, "quiet for 360 ticks: not yet", NULL);
	fake_clock = (uint16_t)(65000 + 361);
	sys_poll();
	check(fake_safe_calls == 1, "quiet for 361 ticks: tripped", NULL);
	fake_clock += 5000;
	sys_poll();
	check(fake_safe_calls == 1, "tripped once per quiet spell", NULL);
	/* a request heard starts the time again */
	SYS_HEARD();
	sys_poll();
	fake_clock += 360;
	sys_poll();
	check(fake_safe_calls == 1, "heard: 360 ticks are not enough", NULL);
	SYS_HEARD();
	sys_poll();
	fake_clock += 360;
	sys_poll();
	check(fake_safe_calls == 1, "heard again", NULL);
	fake_clock += 1;
	sys_poll();
	check(fake_safe_calls == 2, "then 361 quiet ticks trip it again", NULL);
	/* 0: off, never trips */
	expect("S AA 06 00 00 P\r", "SWAAAP\r\n", "");
	fake_clock += 30000;
	sys_poll();
	check(fake_safe_calls == 2, "FAILSAFE 0 never trips", NULL);
	/* 1 ms = 4 ticks (3.6 rounded up), and one more */
	expect("S AA 06 00 01 P\r", "SWAAAP\r\n", "");
	fake_clock += 4;
	sys_poll();
	check(fake_safe_calls == 2, "1 ms: not after 4 ticks", NULL);
	fake_clock += 1;
	sys_poll();
	check(fake_safe_calls == 3, "1 ms: after 5 ticks", NULL);
	/* reset: off again */
	boot();
	expect("S AA 06 S AB 02 P\r", "SWASR0000P\r\n", "");
}

static void test_lost_characters(void)
{
	boot();
	/* characters lost inside one line: the ring ends it with 0x81, ERROR 04 */
	char in[] = "S A0 00 12 P\x81V\r";
	expect_n(in, sizeof in - 1, "ERROR 04\r\nV1.1\r\n", "");
	/* ... or with 0x82 when the line held nothing (spaces, a comment) */
	char in1[] = "   \x82#x\x82V\r";
	expect_n(in1, sizeof in1 - 1, "V1.1\r\n", "");
	/* a run ate the end of "S A0 00" and two whole requests, and the
	 * start of the line after it: three ERROR 04 and one for that line */
	char in2[] = "S A0 00\x80\x03\x00 00 P\x81V\r";
	expect_n(in2, sizeof in2 - 1, "ERROR 04\r\nERROR 04\r\nERROR 04\r\nERROR 04\r\nV1.1\r\n", "");
	/* the run ended at a line end: the line after it is whole */
	char in3[] = "S A0 00\x80\x02\x00V\rV\r";
	expect_n(in3, sizeof in3 - 1, "ERROR 04\r\nERROR 04\r\nV1.1\r\nV1.1\r\n", "");
	/* the count's bytes can be any value, a line end's too: 0x010D */
	boot();
	char in4[] = "V\x80\x0D\x01\rV\r";
	out_len = 0;
	feed(in4, sizeof in4 - 1);
	check(out_len == 0x10D * 10 + 6 && strcmp(out_buf + 0x10D * 10, "V1.1\r\n") == 0,
		"269 lost requests", NULL);
	/* the issue-8 defect: a run that lost only line ends of empty lines
	 * is no request (it had given an extra ERROR 04) */
	boot();
	char in5[] = "V\r\x80\x00\x00\rV\r";
	expect_n(in5, sizeof in5 - 1, "V1.1\r\nV1.1\r\n", "");
	/* and the line going on before the run is gone, not joined to the
	 * next one: "#x" then a lost line end then "V" */
	char in6[] = "#x\x80\x00\x00V\r";
	expect_n(in6, sizeof in6 - 1, "V1.1\r\n", "");
}

/* --- the receive ring (sg_rx.c) in front of the parser --------------------
 * A model of the firmware on a wire at full speed: one character arrives per
 * character time; the main loop takes characters while it is not busy, and
 * a reply keeps it busy for its length times `busy` character times (the
 * transmit side), so replies longer than requests overflow the ring. */
static void wire(const char *in, size_t n, unsigned busy_num, unsigned busy_den)
{
	unsigned busy = 0;  /* in 1/busy_den character times */
	for (size_t i = 0;; i++) {
		if (i < n) {
			sg_rx_put((uint8_t)in[i]);
		}
		busy = busy > busy_den ? busy - busy_den : 0;
		while (busy == 0) {
			int16_t c = sg_rx_get();
			if (c < 0) {
				if (!sg_rx_losing()) {
					break;
				}
				sg_rx_close();
				continue;
			}
			unsigned before = out_len;
			sg_event_t ev = sg_parse_char(&parser, (uint8_t)c);
			if (ev == SG_REQUEST) {
				sg_exec(&parser);
			} else if (ev == SG_LOST) {
				sg_exec_lost(&parser);
			}
			busy = (out_len - before) * busy_num;
		}
		if (i >= n && busy == 0) {
			return;  /* everything taken, the line quiet */
		}
	}
}

static int count_lines(const char *s)
{
	int n = 0;
	for (; *s; s++) {
		n += *s == '\n';
	}
	return n;
}

static void test_receive_overflow(void)
{
	static char in[8192];
	/* issue 8: four 127-character replies, then 330 line ends of empty
	 * lines, then V: five requests, five replies */
	boot();
	in[0] = 0;
	for (int i = 0; i < 4; i++) {
		strcat(in, "S AA 00 01 S AB 3C P\r");
	}
	size_t k = strlen(in);
	memset(in + k, '\n', 330);
	strcpy(in + k + 330, "V\r");
	out_len = 0;
	out_buf[0] = 0;
	wire(in, strlen(in), 1, 1);
	check(count_lines(out_buf) == 5, "4 long replies, 330 empty lines, V: 5 replies", out_buf);
	check(out_len >= 6 && strcmp(out_buf + out_len - 6, "V1.1\r\n") == 0, "V answered last", out_buf);
	/* eleven long replies then 250 line ends, then later a V on an idle
	 * line: twelve replies, the V's V1.1 */
	boot();
	in[0] = 0;
	for (int i = 0; i < 11; i++) {
		strcat(in, "S AA 00 01 S AB 3C P\r");
	}
	k = strlen(in);
	memset(in + k, '\n', 250);
	in[k + 250] = 0;
	out_len = 0;
	out_buf[0] = 0;
	wire(in, strlen(in), 1, 1);
	check(count_lines(out_buf) == 11, "11 long replies then 250 empty lines: 11 replies", out_buf);
	wire("V\r", 2, 1, 1);
	check(count_lines(out_buf) == 12 && strcmp(out_buf + out_len - 6, "V1.1\r\n") == 0,
		"V on an idle line after the run", out_buf);
	/* a line of spaces whose end is lost is no request either, and the
	 * end of a space line that lost spaces gets no reply */
	boot();
	in[0] = 0;
	for (int i = 0; i < 3; i++) {
		strcat(in, "S AA 00 01 S AB 3C P\r");
	}
	k = strlen(in);
	for (int i = 0; i < 60; i++) {
		memcpy(in + k, "     \r\n", 7);
		k += 7;
	}
	strcpy(in + k, "V\r");
	out_len = 0;
	out_buf[0] = 0;
	wire(in, strlen(in), 1, 1);
	check(count_lines(out_buf) == 4 && strcmp(out_buf + out_len - 6, "V1.1\r\n") == 0,
		"lines of spaces lost: no replies", out_buf);
}

/* Random requests over a wire that overflows: every request gets exactly one
 * reply, in order, either the one it gets without overflow or ERROR 04.
 * Only requests whose replies do not depend on what ran before. */
static void test_overflow_fuzz(void)
{
	static const char *const pool[] = {
		"V", "X", "L", "C", "S AA 00 00 S AB 01 P", "S AA 00 01 S AB 3C P",
		"S A0 10 S A1 04 P", "S A0 P", "S 42 P", "Q", "S AA", "V 1", "S A1 00 P",
		"  V  ", "#a comment", "", "   ", "#", " #not a comment", "s aa 00 02 s ab 06 p",
	};
	static const char *const ends[] = { "\r", "\n", "\r\n" };
	static char in[20000];
	static char ref[200000];
	uint32_t seed = 8;
	int bad = 0, overflowed = 0, errors = 0;
	for (int round = 0; round < 400 && bad < 3; round++) {
		size_t n = 0;
		int lines = 0, requests = 0;
		const char *which[400];
		int nreq = 0;
		while (n < 4000 + (size_t)(round % 7) * 2000 && lines < 399) {
			seed ^= seed << 13;
			seed ^= seed >> 17;
			seed ^= seed << 5;
			const char *r = pool[seed % (sizeof pool / sizeof pool[0])];
			const char *e = ends[(seed >> 8) % 3];
			size_t rl = strlen(r), el = strlen(e);
			memcpy(in + n, r, rl);
			memcpy(in + n + rl, e, el);
			n += rl + el;
			lines++;
			bool req = false;
			for (const char *q = r; *q; q++) {
				req |= *q != ' ';
			}
			if (req && r[0] != '#') {
				which[nreq++] = r;
				requests++;
			}
		}
		/* the replies without overflow, one per request */
		boot();
		out_len = 0;
		out_buf[0] = 0;
		feed(in, n);
		if (count_lines(out_buf) != requests) {
			bad++;
			printf("overflow fuzz %d: reference gives %d replies for %d requests\n", round,
				count_lines(out_buf), requests);
			continue;
		}
		memcpy(ref, out_buf, out_len + 1);
		/* the same over a wire three times slower at replying than at
		 * receiving (sometimes not slower: no overflow) */
		boot();
		out_len = 0;
		out_buf[0] = 0;
		unsigned num = 1 + (seed >> 3) % 4, den = 1 + (seed >> 5) % 2;
		wire(in, n, num, den);
		const char *g = out_buf, *w = ref;
		int got = 0, lost_here = 0;
		while (*g && *w) {
			const char *ge = strchr(g, '\n'), *we = strchr(w, '\n');
			if (!ge || !we) {
				break;
			}
			size_t gl = (size_t)(ge - g + 1), wl = (size_t)(we - w + 1);
			bool same = gl == wl && memcmp(g, w, gl) == 0;
			bool refused = gl == 10 && memcmp(g, "ERROR 04\r\n", 10) == 0;
			if (!same && !refused) {
				bad++;
				printf("overflow fuzz %d: reply %d of \"%s\" is \"%.*s\", want \"%.*s\" or ERROR 04\n",
					round, got, which[got], (int)gl - 2, g, (int)wl - 2, w);
				break;
			}
			lost_here += refused && !same;
			got++;
			g = ge + 1;
			w = we + 1;
		}
		int replies = count_lines(out_buf);
		if (replies != requests) {
			bad++;
			printf("overflow fuzz %d (busy %u/%u): %d replies for %d requests\n", round, num, den,
				replies, requests);
		}
		overflowed += lost_here > 0;
		errors += lost_here;
	}
	check(bad == 0, "overflow fuzz: one reply per request, each its own or ERROR 04", NULL);
	check(overflowed > 100 && errors > 1000, "overflow fuzz overflowed", NULL);
}

static void test_registers(void)
{
	boot();
	/* introspection: intro + the fake driver + sys (always last) */
	expect("S AA 00 00 S AB 01 P\r", "SWAASR03P\r\n", "");
	expect("S AA 00 01 S AB 06 P\r", "SWAASR000001000002P\r\n", "");
	expect("S AA 00 02 S AB 06 P\r", "SWAASR0F0F02030203P\r\n", "");
	expect("S AA 00 01 S AB 0C P\r", "SWAASR0000010000020F0F02030203P\r\n", "");
	/* status after a clean read */
	expect("S AA 01 S AB 01 P\r", "SWASR00P\r\n", "");
	/* the count read moves nothing: every byte and frame gives it again */
	expect("S AA 00 00 S AB 03 P\r", "SWAASR030303P\r\n", "");
	expect("S AB 01 S AB 01 P\r", "SR03SR03P\r\n", "");
	/* reading past the last driver goes on with driver 1, status 06 */
	expect("S AA 00 03 S AB 06 P\r", "SWAASR000201000502P\r\n", "");
	expect("S AA 00 03 S AB 0C P\r", "SWAASR000201000502000001000002P\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR06P\r\n", "");
	/* N above the count: ERROR 07, status 02, next read gives driver 1 */
	expect("S AA 00 04 P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR02P\r\n", "");
	expect("S AA 00 S AB 06 P\r", "SWASR000001000002P\r\n", "");
	/* each read frame asks afresh; a short frame drops the rest */
	expect("S AA 00 01 S AB 02 S AB 06 P\r", "SWAASR0000SR0F0F02030203P\r\n", "");
	/* unmapped registers */
	expect("S AA 07 P\r", "ERROR 07\r\n", "");
	expect("S AA FF 00 P\r", "ERROR 07\r\n", "");
	/* the fake driver: +0 at 0x02 read/write, +1 at 0x03 read-only,
	 * +2 at 0x04 write-only */
	expect("S AA 02 S AB 01 P\r", "SWASR5AP\r\n", "");
	expect("S AA 02 01 02 03 S AB 03 P\r", "SWAAAASR010203P\r\n", "");
	/* asked again when its data run out */
	expect("S AA 02 S AB 05 P\r", "SWASR0102030102P\r\n", "");
	/* rejected write changes nothing */
	expect("S AA 02 01 02 03 04 05 P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR01P\r\n", "");
	expect("S AA 02 S AB 03 P\r", "SWASR010203P\r\n", "");
	expect("S AA 03 S AB 03 P\r", "SWASR112233P\r\n", "");
	expect("S AA 03 09 P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR04P\r\n", "");
	expect("S AA 04 09 09 P\r", "SWAAAP\r\n", "");
	expect("S AA 04 S AB 01 P\r", "ERROR 06\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR05P\r\n", "");
	/* status register: not writable, reading it keeps it */
	expect("S AA 01 00 P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 02 P\r", "SWASR0404P\r\n", "");
	/* selecting a register is not an operation: status stays */
	expect("S AA 02 P\r", "SWAP\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR04P\r\n", "");
	/* local and bus frames mixed: STOP only for the bus part */
	expect("S AA 00 00 S A0 00 S AB 01 P\r", "SWAASWASR03P\r\n", "S A0+ W00+ P ");
	/* local probe */
	expect("S AA P\r", "SWP\r\n", "");
	expect("S AB 01 P\r", "SR03P\r\n", "");  /* the count read moved nothing */
	/* an unmapped register: ERROR 07, and the status register says why */
	expect("S AA 7F P\r", "ERROR 07\r\n", "");
	expect("S AA 01 S AB 01 P\r", "SWASR08P\r\n", "");
}

/* Random input must never crash, hang or break the one-reply-per-line rule. */
static void test_fuzz(void)
{
	static const char alphabet[] = "VXLCSPvxlcsp0123456789ABCDEFabcdefGz #\r\n\t\x80\xff";
	uint32_t seed = 12345;
	int bad = 0;
	for (int round = 0; round < 3000 && bad < 5; round++) {
		boot();
		char in[400];
		size_t n = 0, len = 1 + (round % 350);
		for (; n < len; n++) {
			seed ^= seed << 13;
			seed ^= seed >> 17;
			seed ^= seed << 5;
			in[n] = alphabet[seed % (sizeof alphabet - 1)];
		}
		/* expected replies: lines with a non-space character, not starting
		 * with '#' (bytes >= 0x80 from the line are characters like any) */
		int lines = 0, content = 0, comment = 0, first = 1;
		for (size_t i = 0; i < n; i++) {
			char c = in[i];
			if (c == '\r' || c == '\n') {
				if (content && !comment) {
					lines++;
				}
				content = comment = 0;
				first = 1;
				continue;
			}
			if (first && c == '#') {
				comment = 1;
			} else if (c != ' ') {
				content = 1;
			}
			first = 0;
		}
		out_len = 0;
		wire(in, n, 0, 1);  /* through the receive ring, never full */
		int replies = 0;
		for (unsigned i = 0; i + 1 < out_len + 1 && i < out_len; i++) {
			if (out_buf[i] == '\n') {
				replies++;
			}
		}
		if (replies != lines) {
			bad++;
			char a[1600], b[140000];
			in[n] = 0;
			escape(a, sizeof a, in);
			escape(b, sizeof b, out_buf);
			printf("fuzz round %d: %d replies for %d lines: in=\"%s\" out=\"%s\"\n", round, replies, lines, a, b);
		}
		/* every reply line is at most 127 characters */
		unsigned start = 0;
		for (unsigned i = 0; i < out_len; i++) {
			if (out_buf[i] == '\n') {
				if (i - start - 1 > 127) {
					bad++;
					printf("fuzz round %d: reply of %u characters\n", round, i - start - 1);
				}
				start = i + 1;
			}
		}
	}
	check(bad == 0, "fuzz", NULL);
}

/* sg_parse_run() takes from the ring only characters that sg_parse_char()
 * answers SG_MORE, and leaves the parser as sg_parse_char() character by
 * character does; the character it stops at then goes through
 * sg_parse_char(), as in front_poll(). Characters arrive a few
 * at a time (head moves in steps), so runs end anywhere: inside a byte,
 * at the line's limit, at the ring's wrap. */
static void test_parse_run(void)
{
	static const char alphabet[] = "SSPp    0123456789ABCDEFabcdef  0A1B  Gz#VLC\r\n\x80\x81\x82";
	static const char prefix[] = "S 20 01 02 03 04 05 06 07 08 09 0A 0B 0C 0D 0E 0F 10 11 12 "
		"13 14 15 16 17 18 19 1A 1B 1C 1D 1E 1F 20 21 22 23 24 25 26 27 28";
	static sg_parser_t fast, slow;
	static uint8_t ring[256];
	uint32_t seed = 4242;
	int bad = 0;
	unsigned taken = 0;

	for (int round = 0; round < 3000 && !bad; round++) {
		size_t skip = (round & 1) ? (size_t)(round / 2 % 8) : sizeof prefix - 1;
		uint8_t head = (uint8_t)(round * 37), tail = head;
		sg_parse_init(&fast);
		sg_parse_init(&slow);
		size_t len = 1 + (size_t)(round % 400), i = 0;
		while ((i < len || tail != head) && !bad) {
			/* 0..5 more characters arrive */
			seed ^= seed << 13;
			seed ^= seed >> 17;
			seed ^= seed << 5;
			for (unsigned k = seed % 6; k && i < len; k--, i++) {
				seed ^= seed << 13;
				seed ^= seed >> 17;
				seed ^= seed << 5;
				ring[head++] = (uint8_t)(skip + i < sizeof prefix - 1 ? prefix[skip + i] :
							 alphabet[seed % (sizeof alphabet - 1)]);
			}
			if (tail == head) {
				continue;
			}
			uint8_t to = sg_parse_run(&fast, ring, tail, &head);
			for (; tail != to && !bad; tail++) {
				taken++;
				if (sg_parse_char(&slow, ring[tail]) != SG_MORE) {
					check(0, "parse run", "took a character that is not SG_MORE");
					bad = 1;
				}
			}
			if (!bad && memcmp(&fast, &slow, sizeof fast) != 0) {
				check(0, "parse run", "the parser after a run differs");
				bad = 1;
			}
			if (!bad && tail != head) {
				/* the character it stopped at, as front_poll() does */
				uint8_t c = ring[tail++];
				if (sg_parse_char(&fast, c) != sg_parse_char(&slow, c) ||
				    memcmp(&fast, &slow, sizeof fast) != 0) {
					char what[80];
					snprintf(what, sizeof what, "round %d, character 0x%02X", round, c);
					check(0, "parse run then char", what);
					bad = 1;
				}
			}
		}
	}
	check(!bad, "parse run agrees", NULL);
	check(taken > 20000, "parse run takes characters (29700 of them)", NULL);
}

int main(void)
{
	test_simple_commands();
	test_local_address();
	test_clock();
	test_rates();
	test_i2c();
	test_i2c_parse_errors();
	test_limits();
	test_lost_characters();
	test_receive_overflow();
	test_overflow_fuzz();
	test_registers();
	test_sys();
	test_fuzz();
	test_parse_run();
	printf("%d passed, %d failed\n", passed, failed);
	return failed ? 1 : 0;
}
