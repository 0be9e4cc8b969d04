/*
 * Driver unit tests, the part every board shares: harness, introspection,
 * and the rules that are the same on both boards, with each board's
 * register numbers from its board_t. Prints "N passed, N failed".
 */
#include "drv_test.h"

#include "firmware/xact.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int passed, failed;

void check_at(const char *file, int line, int ok, const char *what)
{
	if (ok) {
		passed++;
	} else {
		failed++;
		printf("FAIL %s:%d %s %s\n", file, line, B.name, what);
	}
}

void check_eq_at(const char *file, int line, long got, long want, const char *what)
{
	char detail[256];
	snprintf(detail, sizeof detail, "%s = 0x%lX, want 0x%lX", what, got, want);
	check_at(file, line, got == want, detail);
}

static unsigned parse_hex(const char *hex, uint8_t *dst, unsigned cap)
{
	unsigned n = 0;
	while (*hex) {
		if (*hex == ' ') {
			hex++;
			continue;
		}
		unsigned v;
		if (n == cap || sscanf(hex, "%2x", &v) != 1 || !hex[1]) {
			fprintf(stderr, "bad hex in a test: %s\n", hex);
			exit(2);
		}
		dst[n++] = (uint8_t)v;
		hex += 2;
	}
	return n;
}

static void to_hex(char *dst, const uint8_t *b, unsigned n)
{
	dst[0] = 0;
	for (unsigned i = 0; i < n; i++) {
		sprintf(dst + strlen(dst), "%s%02X", i ? " " : "", b[i]);
	}
}

/* A read frame of n bytes of the selected register, as both front ends
 * make it: through the transaction module. */
static reg_status_t read_n(uint8_t *dst, uint8_t n)
{
	bool ok = xact_read_requested(dst, n);
	for (uint8_t k = 0; k < n && ok; k++) {
		ok = xact_read_processed(&dst[k]);
	}
	xact_frame_end();
	return ok ? REG_OK : REG_NOT_READABLE;
}

static uint8_t status_now(void)
{
	uint8_t st = 0xEE;
	if (!regmap_select(REGMAP_STATUS_REG) || read_n(&st, 1) != REG_OK) {
		return 0xEE;
	}
	return st;
}

/* Selects `reg` for a check at file:line, which fails if no driver maps it. */
static bool select_at(const char *file, int line, uint8_t reg)
{
	if (regmap_select(reg)) {
		return true;
	}
	char what[40];
	snprintf(what, sizeof what, "register %02X not mapped", reg);
	check_at(file, line, 0, what);
	return false;
}

void write_at(const char *file, int line, uint8_t reg, const char *hex, reg_status_t status)
{
	uint8_t data[256];
	unsigned n = parse_hex(hex, data, sizeof data);
	char what[700];
	if (!select_at(file, line, reg)) {
		return;
	}
	reg_status_t got = regmap_write(data, (uint8_t)n);
	uint8_t st = status_now();
	snprintf(what, sizeof what, "write %02X [%s]: result %02X status %02X, want %02X",
		 reg, hex, got, st, status);
	check_at(file, line, got == status && st == status, what);
}

void read_at(const char *file, int line, uint8_t reg, uint8_t n, const char *hex,
	     reg_status_t status)
{
	uint8_t want[256], got[256];
	unsigned wn = parse_hex(hex, want, sizeof want);
	memset(got, 0xEE, sizeof got);
	char what[1200], g[800];
	if (!select_at(file, line, reg)) {
		return;
	}
	reg_status_t r = read_n(got, n);
	uint8_t st = status_now();
	to_hex(g, got, n);
	snprintf(what, sizeof what, "read %02X x%u: [%s] result %02X status %02X, want [%s] status %02X",
		 reg, n, g, r, st, hex, status);
	check_at(file, line, r == REG_OK && st == status && wn == n && memcmp(got, want, n) == 0
		 && got[n] == 0xEE, what);
}

void unreadable_at(const char *file, int line, uint8_t reg, uint8_t n)
{
	uint8_t got[256];
	memset(got, 0xEE, sizeof got);
	char what[200];
	if (!select_at(file, line, reg)) {
		return;
	}
	reg_status_t r = read_n(got, n);
	uint8_t st = status_now();
	int untouched = 1;
	for (unsigned i = 0; i < n; i++) {
		untouched &= got[i] == 0xEE;
	}
	snprintf(what, sizeof what, "read %02X x%u: result %02X status %02X, want 05 05 (filled: %s)",
		 reg, n, r, st, untouched ? "no" : "yes");
	check_at(file, line, r == REG_NOT_READABLE && st == REG_NOT_READABLE && untouched, what);
}

void boot(void)
{
	hw_fakes_reset();
	pins_init();
	regmap_init();
}

void snap_take(snap_t *s)
{
	memset(s, 0, sizeof *s);
	memcpy(s->out, port_out, sizeof s->out);
	memcpy(s->ddr, port_ddr, sizeof s->ddr);
	for (unsigned p = 0; p < sizeof s->owner; p++) {
		s->owner[p] = (uint8_t)pins_owner((uint8_t)p);
	}
	s->hw = hw;
	/* Every register but introspection (its reads move its cursor) and
	 * status. */
	for (unsigned reg = 2; reg < B.nregs; reg++) {
		if (!regmap_select((uint8_t)reg)) {
			continue;
		}
		s->readable[reg] = read_n(s->regs[reg], 64) == REG_OK;
		if (!s->readable[reg]) {
			memset(s->regs[reg], 0, 64);
		}
	}
}

void same_at(const char *file, int line, const snap_t *before)
{
	snap_t *now = malloc(sizeof *now);
	snap_take(now);
	char what[200];
	for (unsigned p = 0; p < BOARD_NPORTS; p++) {
		snprintf(what, sizeof what, "port %c: PORT %02X DDR %02X, was %02X %02X", 'A' + p,
			 now->out[p], now->ddr[p], before->out[p], before->ddr[p]);
		check_at(file, line, now->out[p] == before->out[p] && now->ddr[p] == before->ddr[p], what);
	}
	check_at(file, line, memcmp(now->owner, before->owner, sizeof now->owner) == 0,
		 "pin owners unchanged");
	check_at(file, line, memcmp(&now->hw, &before->hw, sizeof now->hw) == 0,
		 "hardware records unchanged");
	for (unsigned reg = 2; reg < B.nregs; reg++) {
		snprintf(what, sizeof what, "register %02X reads as before", reg);
		check_at(file, line, now->readable[reg] == before->readable[reg]
			 && memcmp(now->regs[reg], before->regs[reg], 64) == 0, what);
	}
	free(now);
}

void refused_writes_at(const char *file, int line, uint8_t reg, reg_status_t status,
		       const char *const *hex)
{
	snap_t *before = malloc(sizeof *before);
	snap_take(before);
	for (; *hex; hex++) {
		write_at(file, line, reg, *hex, status);
	}
	same_at(file, line, before);
	free(before);
}

/* --- introspection and the register map ------------------------------------ */

static void test_intro(void)
{
	uint8_t want[64];
	unsigned n = parse_hex(B.intro, want, sizeof want);
	char hex[200], rec[40];

	boot();
	CHECK_EQ(n, 6u * B.ndrivers);
	CHECK_EQ(regmap_driver_count(), B.ndrivers);
	/* The records are contiguous from 0x00 and end at the last register. */
	unsigned next = 0;
	for (unsigned d = 0; d < B.ndrivers; d++) {
		CHECK_EQ(want[6 * d + 4], next);
		next += want[6 * d + 5];
	}
	CHECK_EQ(next, B.nregs);

	/* After reset 0x00 is selected: the first read is the count. */
	uint8_t b = 0;
	CHECK_EQ(read_n(&b, 1), REG_OK);
	CHECK_EQ(b, B.ndrivers);

	char cnt[4];
	snprintf(cnt, sizeof cnt, "%02X", B.ndrivers);
	WRITE(0x00, "00", REG_OK);
	READ(0x00, 1, cnt);
	for (unsigned d = 1; d <= B.ndrivers; d++) {
		snprintf(cnt, sizeof cnt, "%02X", d);
		to_hex(rec, &want[6 * (d - 1)], 6);
		WRITE(0x00, cnt, REG_OK);
		READ(0x00, 6, rec);
	}
	/* 6k bytes: k consecutive drivers; every driver in one read. */
	to_hex(hex, want, n);
	WRITE(0x00, "01", REG_OK);
	READ(0x00, (uint8_t)n, hex);
	/* Reading the count moves nothing (docs/registers.md, as ORFA 0.7.5): every read
	 * frame, and every byte of a longer one, gives the count again. */
	char buf[220];
	WRITE(0x00, "00", REG_OK);
	snprintf(buf, sizeof buf, "%02X %02X %02X", B.ndrivers, B.ndrivers, B.ndrivers);
	READ(0x00, 3, buf);
	snprintf(buf, sizeof buf, "%02X", B.ndrivers);
	READ(0x00, 1, buf);
	READ(0x00, 1, buf);
	/* Past the last driver: driver 1 again, status 06. */
	snprintf(cnt, sizeof cnt, "%02X", B.ndrivers);
	WRITE(0x00, cnt, REG_OK);
	to_hex(rec, &want[6 * (B.ndrivers - 1)], 6);
	snprintf(buf, sizeof buf, "%s 00 00 01 00 00 02", rec);
	READ_ST(0x00, 12, buf, REG_READ_WRAPPED);
	/* Reading the status leaves it: still 06. */
	uint8_t st[3] = { 0, 0, 0 };
	regmap_select(REGMAP_STATUS_REG);
	CHECK_EQ(read_n(st, 3), REG_OK);
	CHECK_EQ(st[0] << 16 | st[1] << 8 | st[2], 0x060606);
	/* Selecting a register is not an operation: status stays 06. */
	CHECK(regmap_select(0x00));
	CHECK(regmap_select(B.nregs - 1));
	regmap_select(REGMAP_STATUS_REG);
	read_n(st, 1);
	CHECK_EQ(st[0], REG_READ_WRAPPED);
	/* ... and the cursor after the wrap goes on with driver 2. */
	to_hex(rec, &want[6], 6);
	READ(0x00, 6, rec);

	/* N above the count: 02, next read driver 1 (even after a count read). */
	snprintf(cnt, sizeof cnt, "%02X", B.ndrivers + 1);
	WRITE(0x00, "00", REG_OK);
	WRITE(0x00, cnt, REG_BAD_VALUE);
	to_hex(rec, want, 6);
	READ(0x00, 6, rec);
	WRITE(0x00, "FF", REG_BAD_VALUE);
	READ(0x00, 6, rec);
	/* More than one byte: 01, cursor left alone. */
	WRITE(0x00, "03", REG_OK);
	WRITE(0x00, "02 00", REG_BAD_LENGTH);
	to_hex(rec, &want[12], 6);
	READ(0x00, 6, rec);
	/* A partial record: the next read goes on with the next driver. */
	WRITE(0x00, "02", REG_OK);
	to_hex(rec, &want[6], 3);
	READ(0x00, 3, rec);
	to_hex(rec, &want[12], 6);
	READ(0x00, 6, rec);

	/* The status register cannot be written: 04, and it says so. */
	WRITE(REGMAP_STATUS_REG, "00", REG_NOT_WRITABLE);
	/* Registers past the map are not acknowledged, and then none is
	 * selected: a read gives nothing, the status says 08 (not the
	 * register selected before: introspection's count here). */
	const uint8_t zero = 0;
	CHECK(regmap_select(0x00));
	CHECK_EQ(regmap_write(&zero, 1), REG_OK);
	CHECK(!regmap_select(B.nregs));
	CHECK(!regmap_select(0xFF));
	uint8_t c = 0xEE;
	CHECK_EQ(read_n(&c, 1), REG_NOT_READABLE);
	CHECK_EQ(c, 0xEE);
	CHECK_EQ(regmap_status(), REG_NO_REGISTER);
	CHECK_EQ(regmap_write(&zero, 1), REG_NO_REGISTER);
	CHECK(regmap_select(0x00));
	CHECK_EQ(read_n(&c, 1), REG_OK);
	CHECK_EQ(c, B.ndrivers);
}

/* --- GPIO ------------------------------------------------------------------ */

static void test_gpio_common(void)
{
	boot();
	/* After reset: every line an input without pull-up. */
	for (unsigned i = 0; i < B.gpio_nports; i++) {
		READ(B.gpio_mode + i, 1, "00");
		READ(B.gpio_value + i, 1, "00");
	}
	/* The GPIO port that is the ADC port has all eight lines free at reset
	 * on both boards (nothing else claims them until enabled). */
	uint8_t vr = (uint8_t)(B.gpio_value + B.adc_gpio);
	uint8_t mr = (uint8_t)(B.gpio_mode + B.adc_gpio);
	uint8_t p = B.adc_port;

	WRITE(mr, "0F", REG_OK);
	CHECK_EQ(port_ddr[p], 0x0F);
	READ(mr, 1, "0F");
	/* Value on outputs: level; on inputs: pull-ups. Reads give the pins. */
	WRITE(vr, "A5", REG_OK);
	CHECK_EQ(port_out[p], 0xA5);
	port_ext[p] = 0x3C;
	/* outputs 0-3 show PORT (5), inputs 4-7 show outside levels (3) */
	READ(vr, 1, "35");
	/* Mask: only lines 0 and 7 change. */
	WRITE(vr, "00 81", REG_OK);
	CHECK_EQ(port_out[p], 0x24);
	WRITE(mr, "FF 30", REG_OK);
	CHECK_EQ(port_ddr[p], 0x3F);
	READ(mr, 1, "3F");
	WRITE(mr, "00 00", REG_OK);
	CHECK_EQ(port_ddr[p], 0x3F);
	/* Value and mode registers of the other ports leave this one alone. */
	for (unsigned i = 0; i < B.gpio_nports; i++) {
		if (i == B.adc_gpio) {
			continue;
		}
		WRITE(B.gpio_value + i, "00", REG_OK);
		WRITE(B.gpio_mode + i, "00", REG_OK);
	}
	CHECK_EQ(port_out[p], 0x24);
	CHECK_EQ(port_ddr[p], 0x3F);

	/* Lengths other than 1 or 2: 01, nothing changes. */
	REFUSED(vr, REG_BAD_LENGTH, "11 22 33", "");
	REFUSED(mr, REG_BAD_LENGTH, "", "FF FF FF");
}

/* --- servos ---------------------------------------------------------------- */

static void test_servo_common(void)
{
	uint8_t sp = B.servo_sp, rs = B.servo_rs;
	char want[200];

	boot();
	CHECK_EQ(hw.servo_inits, 1);
	/* After reset nothing pulses: all widths 0. */
	READ(sp, 8, "00 00 00 00 00 00 00 00");
	READ(rs, (uint8_t)(B.servo_channels / 8), B.servo_channels == 16 ? "00 00" : "00 00 00 00");

	/* One triple; widths go to the hardware together. */
	WRITE(sp, "05 05 DC", REG_OK);
	CHECK_EQ(hw.servo_applies, 1);
	CHECK_EQ(hw.servo_width[5], 1500);
	CHECK_EQ(hw.servo_claimed[5], 1);
	READ(sp, 12, "00 00 00 00 00 00 00 00 00 00 05 DC");

	/* Clamping: 0 off, 1 and 499 -> 500, 500, 2500, 2501 and FFFF -> 2500. */
	WRITE(sp, "00 00 01 01 01 F3 02 01 F4 03 09 C4 04 09 C5 06 FF FF", REG_OK);
	READ(sp, 14, "01 F4 01 F4 01 F4 09 C4 09 C4 05 DC 09 C4");
	CHECK_EQ(hw.servo_width[0], 500);
	CHECK_EQ(hw.servo_width[1], 500);
	CHECK_EQ(hw.servo_width[2], 500);
	CHECK_EQ(hw.servo_width[3], 2500);
	CHECK_EQ(hw.servo_width[4], 2500);
	CHECK_EQ(hw.servo_width[6], 2500);
	/* 0 turns a channel off and gives its pins back. */
	unsigned rel = hw.servo_releases;
	WRITE(sp, "05 00 00", REG_OK);
	CHECK_EQ(hw.servo_width[5], 0);
	CHECK_EQ(hw.servo_claimed[5], 0);
	CHECK_EQ(hw.servo_releases, rel + 1);
	READ(sp, 12, "01 F4 01 F4 01 F4 09 C4 09 C4 00 00");
	/* A width change on a pulsing channel claims nothing again. */
	unsigned claims = hw.servo_claims;
	WRITE(sp, "00 04 B0", REG_OK);
	CHECK_EQ(hw.servo_claims, claims);
	CHECK_EQ(hw.servo_width[0], 1200);
	/* Later triples win over earlier ones for the same channel. */
	WRITE(sp, "07 03 E8 07 07 D0", REG_OK);
	CHECK_EQ(hw.servo_width[7], 2000);

	/* RS: accepted, changes nothing; reads the pulsing mask, highest
	 * channel first: channels 0-4, 6, 7 pulse. */
	snap_t *s = malloc(sizeof *s);
	snap_take(s);
	const char *mask = B.servo_channels == 16 ? "00 DF" : "00 00 00 DF";
	READ(rs, (uint8_t)(B.servo_channels / 8), mask);
	WRITE(rs, "FF FF", REG_OK);
	WRITE(rs, "00", REG_OK);
	WRITE(rs, "12 34 56 78 9A", REG_OK);
	SAME(s);
	/* The highest channel is bit 7 of the first byte. */
	char t[40];
	snprintf(t, sizeof t, "%02X 05 DC", B.servo_channels - 1);
	WRITE(sp, t, REG_OK);
	READ(rs, (uint8_t)(B.servo_channels / 8), B.servo_channels == 16 ? "80 DF" : "80 00 00 DF");
	/* Reading fewer bytes of RS gives the first (highest) bytes. */
	READ(rs, 1, "80");

	/* Rejections change nothing. */
	snap_take(s);
	/* channel out of range in any triple: 02 */
	snprintf(t, sizeof t, "00 05 DC %02X 05 DC", B.servo_channels);
	WRITE(sp, t, REG_BAD_VALUE);
	snprintf(t, sizeof t, "%02X 05 DC 01 05 DC", B.servo_channels);
	WRITE(sp, t, REG_BAD_VALUE);
	WRITE(sp, "FF 00 00", REG_BAD_VALUE);
	/* lengths not a multiple of 3 (above 1): 01 */
	WRITE(sp, "00 05", REG_BAD_LENGTH);
	WRITE(sp, "00 05 DC 01", REG_BAD_LENGTH);
	WRITE(sp, "00 05 DC 01 05", REG_BAD_LENGTH);
	/* length beats channel: a bad length with a bad channel is 01 */
	WRITE(sp, "FF 05", REG_BAD_LENGTH);
	/* 17 triples: 01 */
	char big[400] = "";
	for (unsigned i = 0; i < 17; i++) {
		sprintf(big + strlen(big), "%02X 03 E8 ", i % 8);
	}
	WRITE(sp, big, REG_BAD_LENGTH);
	/* selection byte out of range: 02 */
	snprintf(t, sizeof t, "%02X", B.servo_channels);
	WRITE(sp, t, REG_BAD_VALUE);
	SAME(s);

	/* 16 triples: accepted, all applied at once. */
	boot();
	big[0] = 0;
	for (unsigned i = 0; i < 16; i++) {
		sprintf(big + strlen(big), "%02X %02X %02X ", i, (1000 + 10 * i) >> 8, (1000 + 10 * i) & 0xFF);
	}
	WRITE(sp, big, REG_OK);
	CHECK_EQ(hw.servo_applies, 1);
	for (unsigned i = 0; i < 16; i++) {
		CHECK_EQ(hw.servo_width[i], 1000 + 10 * i);
		CHECK_EQ(hw.servo_claimed[i], 1);
	}
	want[0] = 0;
	for (unsigned i = 0; i < 16; i++) {
		sprintf(want + strlen(want), "%02X %02X ", (1000 + 10 * i) >> 8, (1000 + 10 * i) & 0xFF);
	}
	want[strlen(want) - 1] = 0;
	READ(sp, 32, want);

	/* Selection byte: reads start at that channel. */
	WRITE(sp, "0E", REG_OK);
	CHECK_EQ(hw.servo_applies, 1);
	READ(sp, 4, "04 74 04 7E");
	/* An odd count gives the high byte of the last channel. */
	READ(sp, 3, "04 74 04");
	/* Each read frame starts at the selected channel again. */
	READ(sp, 2, "04 74");
	/* Last channel: past it the driver is asked again from the selection. */
	snprintf(t, sizeof t, "%02X", B.servo_channels - 1);
	WRITE(sp, t, REG_OK);
	if (B.servo_channels == 16) {
		READ(sp, 6, "04 7E 04 7E 04 7E");
	} else {
		READ(sp, 6, "00 00 00 00 00 00");
	}
	/* A triple does not move the selection. */
	WRITE(sp, "00", REG_OK);
	WRITE(sp, "01 00 00", REG_OK);
	READ(sp, 4, "03 E8 00 00");
	free(s);
}

/* --- SPI ------------------------------------------------------------------- */

static void test_spi_common(void)
{
	uint8_t cfg = B.spi_config, data = B.spi_data;
	char t[300];

	boot();
	/* After reset: 02 = divider 2, mode 0, MSB first; nothing bound. */
	CHECK_EQ(hw.spi_inits, 1);
	CHECK_EQ(hw.spi_configs, 1);
	CHECK_EQ(hw.spi_div, 2);
	CHECK_EQ(hw.spi_mode, 0);
	CHECK_EQ(hw.spi_lsb, 0);
	READ(cfg, 9, "02 FF FF FF FF FF FF FF FF");

	/* Bus settings: divider bits 0-2, mode bits 3-4 (4 CPOL, 3 CPHA),
	 * bit 5 LSB first; x is ignored. */
	WRITE(cfg, "FF 00 06", REG_OK);
	CHECK_EQ(hw.spi_div, 6);
	CHECK_EQ(hw.spi_mode, 0);
	CHECK_EQ(hw.spi_lsb, 0);
	WRITE(cfg, "FF 5A 08", REG_OK);   /* CPHA only: mode 1 */
	CHECK_EQ(hw.spi_div, 0);
	CHECK_EQ(hw.spi_mode, 1);
	WRITE(cfg, "FF 00 10", REG_OK);   /* CPOL only: mode 2 */
	CHECK_EQ(hw.spi_mode, 2);
	WRITE(cfg, "FF FF 3D", REG_OK);   /* mode 3, LSB first, divider 5 */
	CHECK_EQ(hw.spi_div, 5);
	CHECK_EQ(hw.spi_mode, 3);
	CHECK_EQ(hw.spi_lsb, 1);
	CHECK_EQ(hw.spi_configs, 5);
	READ(cfg, 9, "3D FF FF FF FF FF FF FF FF");
	READ(cfg, 1, "3D");
	/* Bits 6-7 must be 0: 02, nothing changes. */
	snap_t *s = malloc(sizeof *s);
	snap_take(s);
	WRITE(cfg, "FF 00 40", REG_BAD_VALUE);
	WRITE(cfg, "FF 00 80", REG_BAD_VALUE);
	WRITE(cfg, "FF 00 C2", REG_BAD_VALUE);
	/* CONFIG takes exactly 3 bytes. */
	WRITE(cfg, "FF 00", REG_BAD_LENGTH);
	WRITE(cfg, "FF 00 02 00", REG_BAD_LENGTH);
	WRITE(cfg, "00", REG_BAD_LENGTH);
	/* Channel above 3, port or line out of range: 02. */
	WRITE(cfg, "04 00 03", REG_BAD_VALUE);
	WRITE(cfg, "FE 00 03", REG_BAD_VALUE);
	snprintf(t, sizeof t, "00 %02X 03", B.gpio_nports);
	WRITE(cfg, t, REG_BAD_VALUE);
	WRITE(cfg, "00 FF 03", REG_BAD_VALUE);
	WRITE(cfg, "00 00 08", REG_BAD_VALUE);
	WRITE(cfg, "00 00 FF", REG_BAD_VALUE);
	/* DATA before any exchange cannot be read. */
	UNREADABLE(data, 1);
	/* DATA to an unbound channel: 07; to channel 4: 02; bad lengths: 01. */
	WRITE(data, "00 9F", REG_NOT_BOUND);
	WRITE(data, "03 9F 00", REG_NOT_BOUND);
	WRITE(data, "04 9F", REG_BAD_VALUE);
	WRITE(data, "00", REG_BAD_LENGTH);
	WRITE(data, "", REG_BAD_LENGTH);
	SAME(s);
	CHECK_EQ(hw.spi_bytes, 0);
	UNREADABLE(data, 1);

	/* Bind channel 1 to line 3 of GPIO port 0 (port A on both boards):
	 * the line becomes an output, high, and leaves GPIO. */
	WRITE(B.gpio_mode, "00", REG_OK);
	hw_log_clear();
	WRITE(cfg, "01 00 03", REG_OK);
	CHECK_EQ(pins_owner(PIN(B.gpio_port[0], 3)), PIN_SPI_CS);
	CHECK_EQ(port_ddr[B.gpio_port[0]] & 0x08, 0x08);
	CHECK_EQ(port_out[B.gpio_port[0]] & 0x08, 0x08);
	CHECK_EQ(strcmp(hw_log, "WA08:08 DA08:08 "), 0);
	READ(cfg, 9, "3D FF FF 00 03 FF FF FF FF");
	/* GPIO cannot change it any more. */
	WRITE(B.gpio_value, "00", REG_OK);
	WRITE(B.gpio_mode, "00", REG_OK);
	CHECK_EQ(port_ddr[B.gpio_port[0]], 0x08);
	CHECK_EQ(port_out[B.gpio_port[0]], 0x08);
	READ(B.gpio_mode, 1, "08");
	READ(B.gpio_value, 1, "08");
	/* Binding it again to the same channel: fine, no change. */
	hw_log_clear();
	WRITE(cfg, "01 00 03", REG_OK);
	CHECK_EQ(strcmp(hw_log, ""), 0);
	/* Another channel wants the same line: 03. */
	REFUSED(cfg, REG_PIN_BUSY, "02 00 03");

	/* Exchange: chip select low, bytes, chip select high, nothing else. */
	static const uint8_t answer[] = { 0xC2, 0x20, 0x17, 0x99 };
	spi_script(answer, sizeof answer);
	hw_log_clear();
	WRITE(data, "01 9F 00 00", REG_OK);
	snprintf(t, sizeof t, "WA08:00 X9F0000>C22017 WA08:08 ");
	if (strcmp(hw_log, t) != 0) {
		printf("  log: %s\n  want: %s\n", hw_log, t);
	}
	CHECK_EQ(strcmp(hw_log, t), 0);
	CHECK_EQ(port_out[B.gpio_port[0]] & 0x08, 0x08);
	READ(data, 3, "C2 20 17");
	/* Fewer bytes give the first ones; more ask the driver again. */
	READ(data, 2, "C2 20");
	READ(data, 7, "C2 20 17 C2 20 17 C2");
	/* A rejected exchange keeps the last bytes. */
	WRITE(data, "00 01", REG_NOT_BOUND);
	READ(data, 3, "C2 20 17");
	/* 64 bytes at most: 65 is 01, 64 is fine. */
	char big[400] = "01";
	for (unsigned i = 0; i < 65; i++) {
		sprintf(big + strlen(big), " %02X", i);
	}
	WRITE(data, big, REG_BAD_LENGTH);
	READ(data, 3, "C2 20 17");
	big[strlen(big) - 3] = 0;
	uint8_t miso[64];
	for (unsigned i = 0; i < 64; i++) {
		miso[i] = (uint8_t)(0x80 + i);
	}
	spi_script(miso, 64);
	hw_log_clear();
	WRITE(data, big, REG_OK);
	CHECK_EQ(strncmp(hw_log, "WA08:00 X000102", 15), 0);
	CHECK_EQ(strcmp(hw_log + strlen(hw_log) - 8, "WA08:08 "), 0);
	char want[300] = "";
	for (unsigned i = 0; i < 64; i++) {
		sprintf(want + strlen(want), "%s%02X", i ? " " : "", 0x80 + i);
	}
	READ(data, 64, want);
	/* The one-byte exchange. */
	spi_script(answer + 3, 1);
	WRITE(data, "01 5A", REG_OK);
	READ(data, 2, "99 99");

	/* Rebinding channel 1: the old line goes back to GPIO (input, no
	 * pull-up), the new one is an output, high. */
	hw_log_clear();
	WRITE(cfg, "01 00 06", REG_OK);
	CHECK_EQ(pins_owner(PIN(B.gpio_port[0], 3)), PIN_FREE);
	CHECK_EQ(pins_owner(PIN(B.gpio_port[0], 6)), PIN_SPI_CS);
	CHECK_EQ(port_ddr[B.gpio_port[0]], 0x40);
	CHECK_EQ(port_out[B.gpio_port[0]], 0x40);
	READ(cfg, 9, "3D FF FF 00 06 FF FF FF FF");
	/* Now the old line is GPIO's again. */
	WRITE(B.gpio_mode, "08 08", REG_OK);
	CHECK_EQ(port_ddr[B.gpio_port[0]], 0x48);
	/* Exchanges use the new line. */
	spi_script(answer, 1);
	hw_log_clear();
	WRITE(data, "01 AA", REG_OK);
	CHECK_EQ(strcmp(hw_log, "WA40:00 XAA>C2 WA40:40 "), 0);
	/* Channel 0 to the line the GPIO write above made an output: fine. */
	WRITE(cfg, "00 00 03", REG_OK);
	/* Channel 3 on the last line of the last GPIO port. */
	snprintf(t, sizeof t, "03 %02X 07", B.gpio_nports - 1);
	WRITE(cfg, t, REG_OK);
	CHECK_EQ(pins_owner(PIN(B.gpio_port[B.gpio_nports - 1], 7)), PIN_SPI_CS);
	snprintf(t, sizeof t, "3D 00 03 00 06 FF FF %02X 07", B.gpio_nports - 1);
	READ(cfg, 9, t);
	free(s);
}

/* --- ADC ------------------------------------------------------------------- */

static void test_adc_common(void)
{
	uint8_t rc = B.adc_rc, rd = B.adc_rd, p = B.adc_port;

	boot();
	CHECK_EQ(hw.adc_configs, 1);
	CHECK_EQ(hw.adc_refs, 0);
	CHECK_EQ(hw.adc_mask, 0);
	READ(rc, 2, "00 00");
	/* Nothing enabled: every channel reads 0, whatever is on the pins. */
	for (unsigned ch = 0; ch < 8; ch++) {
		adc_in[ch] = (uint16_t)(0x100 * (ch & 3) + 0x10 * ch + 3);
	}
	READ(rd, 8, "00 00 00 00 00 00 00 00");

	/* The GPIO lines of the port are set up first, to see that enabled
	 * lines become inputs without pull-up and the others stay. */
	WRITE(B.gpio_mode + B.adc_gpio, "FF", REG_OK);
	WRITE(B.gpio_value + B.adc_gpio, "FF", REG_OK);

	/* 8-bit, AVCC, channels 0, 2, 7. */
	WRITE(rc, "01 85", REG_OK);
	CHECK_EQ(hw.adc_refs, 1);
	CHECK_EQ(hw.adc_mask, 0x85);
	CHECK_EQ(port_ddr[p], 0x7A);
	CHECK_EQ(port_out[p], 0x7A);
	for (unsigned ch = 0; ch < 8; ch++) {
		CHECK_EQ(pins_owner(PIN(p, ch)), (0x85 >> ch) & 1 ? PIN_ADC : PIN_FREE);
	}
	READ(rc, 2, "01 85");
	READ(rc, 1, "01");
	/* adc_in: ch0 003, ch2 223, ch7 373: 8-bit = value >> 2. */
	READ(rd, 8, "00 00 88 00 00 00 00 DC");
	READ(rd, 3, "00 00 88");
	/* GPIO cannot touch enabled lines. */
	WRITE(B.gpio_mode + B.adc_gpio, "FF", REG_OK);
	WRITE(B.gpio_value + B.adc_gpio, "FF", REG_OK);
	CHECK_EQ(port_ddr[p], 0x7A);
	CHECK_EQ(port_out[p], 0x7A);

	/* 10-bit, internal: two bytes per channel, big-endian. */
	WRITE(rc, "06 85", REG_OK);
	CHECK_EQ(hw.adc_refs, 3);
	READ(rd, 16, "00 03 00 00 02 23 00 00 00 00 00 00 00 00 03 73");
	/* Fewer bytes: the first channels; an odd count ends on a high byte. */
	READ(rd, 5, "00 03 00 00 02");
	READ(rd, 1, "00");
	/* More than one answer: the driver is asked again from channel 0. */
	READ(rd, 18, "00 03 00 00 02 23 00 00 00 00 00 00 00 00 03 73 00 03");
	WRITE(rc, "07 85", REG_OK);
	CHECK_EQ(hw.adc_refs, 3);
	WRITE(rc, "04 85", REG_OK);
	CHECK_EQ(hw.adc_refs, 0);
	READ(rc, 2, "04 85");
	/* Full-scale values. */
	adc_in[0] = 0x3FF;
	READ(rd, 2, "03 FF");
	WRITE(rc, "00 85", REG_OK);
	READ(rd, 1, "FF");

	/* Changing the mask: lines leaving go back to GPIO (input, no
	 * pull-up), lines joining become the ADC's; unchanged ones stay. */
	WRITE(rc, "01 0C", REG_OK);
	CHECK_EQ(hw.adc_mask, 0x0C);
	for (unsigned ch = 0; ch < 8; ch++) {
		CHECK_EQ(pins_owner(PIN(p, ch)), (0x0C >> ch) & 1 ? PIN_ADC : PIN_FREE);
	}
	CHECK_EQ(port_ddr[p], 0x72);
	CHECK_EQ(port_out[p], 0x72);
	READ(rd, 8, "00 00 88 CC 00 00 00 00");
	/* Mask 0 gives every line back. */
	WRITE(rc, "01 00", REG_OK);
	CHECK_EQ(pins_gpio_mask(p), 0xFF);
	CHECK_EQ(port_ddr[p], 0x72);
	READ(rd, 8, "00 00 00 00 00 00 00 00");
	WRITE(B.gpio_mode + B.adc_gpio, "FF", REG_OK);
	CHECK_EQ(port_ddr[p], 0xFF);

	/* Rejections change nothing. */
	WRITE(rc, "05 33", REG_OK);
	REFUSED(rc, REG_BAD_VALUE, "08 33", "F8 33", "80 00");
	REFUSED(rc, REG_BAD_LENGTH, "01", "01 33 00", "");
	/* RD cannot be written. */
	REFUSED(rd, REG_NOT_WRITABLE, "00 00", "00");
}

/* The link-loss failsafe (regmap_safe()): every servo channel off, as a
 * host's writes of width 0 would; other drivers left as they are (motors:
 * test_drv_m32d.c). */
static void test_failsafe_common(void)
{
	uint8_t sp = B.servo_sp;
	uint8_t last = (uint8_t)(B.servo_channels - 1);
	char hex[40];

	boot();
	snprintf(hex, sizeof hex, "00 05 DC %02X 03 E8", last);
	WRITE(sp, hex, REG_OK);
	CHECK_EQ(hw.servo_claimed[0], 1);
	CHECK_EQ(hw.servo_claimed[last], 1);
	unsigned applies = hw.servo_applies;
	regmap_safe();
	CHECK(hw.servo_applies > applies);
	for (unsigned ch = 0; ch < B.servo_channels; ch++) {
		CHECK_EQ(hw.servo_width[ch], 0);
		CHECK_EQ(hw.servo_claimed[ch], 0);
	}
	READ(sp, 4, "00 00 00 00");
	snprintf(hex, sizeof hex, "%02X", last);
	WRITE(sp, hex, REG_OK);
	READ(sp, 2, "00 00");
	/* nothing pulsing: nothing to do, no new schedule */
	applies = hw.servo_applies;
	regmap_safe();
	CHECK_EQ(hw.servo_applies, applies);
}

int main(void)
{
	test_intro();
	test_failsafe_common();
	test_gpio_common();
	test_servo_common();
	test_spi_common();
	test_adc_common();
	board_tests();
	xact_tests();
	printf("%s: %d passed, %d failed\n", B.name, passed, failed);
	return failed ? 1 : 0;
}
