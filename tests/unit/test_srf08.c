/*
 * The simulator's SRF08 range finder (sim/parts/srf08.c) on the host,
 * driven through its twi_dev_t callbacks as the bus would drive it, with a
 * bus whose time the test sets. Checks the examples and numbers of
 * Devantech's SRF08 technical specification: the ranging sequence (command
 * 0x51 to location 0, 65 ms, result in locations 2,3), the bus left alone
 * while ranging, the range register's ((R x 43) + 43) mm and its examples,
 * the address change in four separate writes, the light reading taken at
 * the ping, ANN mode's 3 m -> location 12. Prints "srf08: N passed, N failed".
 */
#include <stdio.h>
#include <string.h>

#include "parts/srf08.h"

#define HZ ((uint32_t)F_CPU)	/* the boards' clock (make passes board.h's) */
#define MS65 ((uint32_t)((uint64_t)HZ * 65u / 1000u))	/* 65 ms at HZ */

static int passed, failed;
static twi_bus_t bus;
static srf08_t s;

static void check(int ok, const char *what, long got, long want)
{
	if (ok) {
		passed++;
	} else {
		failed++;
		printf("FAIL srf08: %s: got %ld, want %ld\n", what, got, want);
	}
}

static void eq(long got, long want, const char *what)
{
	check(got == want, what, got, want);
}

/* --- the bus, one event at a time ---------------------------------------- */

static int ev_addr(uint64_t t, uint8_t a8)
{
	bus.cycle = t;
	return s.dev.ops->start(&s.dev, a8);
}

static int ev_write(uint64_t t, uint8_t b)
{
	bus.cycle = t;
	return s.dev.ops->write(&s.dev, b);
}

static uint8_t ev_read(uint64_t t, int ack)
{
	bus.cycle = t;
	(void)ack;
	return s.dev.ops->read(&s.dev);
}

static void ev_stop(uint64_t t)
{
	bus.cycle = t;
	s.dev.ops->stop(&s.dev);
}

/* S A8 LOC DATA.. P at cycle T, stopping at the first NACK as a master
 * does. Returns how many bytes were acknowledged (address included). */
static int write_loc(uint64_t t, uint8_t a8, uint8_t loc, const uint8_t *data, int n)
{
	int acks = 0;

	if (ev_addr(t, a8)) {
		acks++;
		if (ev_write(t, loc)) {
			acks++;
			for (int i = 0; i < n && ev_write(t, data[i]); i++) {
				acks++;
			}
		}
	}
	ev_stop(t);
	return acks;
}

static int command(uint64_t t, uint8_t a8, uint8_t cmd)
{
	return write_loc(t, a8, 0, &cmd, 1);
}

/* S A8 LOC S A8|1 (N bytes) P at cycle T: 0, or -1 when an address was
 * not acknowledged (OUT then holds what a master would read: FF). */
static int read_loc(uint64_t t, uint8_t a8, int loc, uint8_t *out, int n)
{
	int ok = 1;

	if (loc >= 0) {
		ok = ev_addr(t, a8) && ev_write(t, (uint8_t)loc);
	}
	ok = ok && ev_addr(t, a8 | 1);
	for (int i = 0; i < n; i++) {
		out[i] = ok ? ev_read(t, i + 1 < n) : 0xff;
	}
	ev_stop(t);
	return ok ? 0 : -1;
}

static long echo(uint64_t t, uint8_t a8, int k)
{
	uint8_t b[2];

	if (read_loc(t, a8, 2 + 2 * k, b, 2) < 0) {
		return -1;
	}
	return b[0] << 8 | b[1];
}

/* Targets at NEAR_MM and FAR_MM (0: none) in front, the ranging command
 * CMD to 0xE0 at cycle T: returns the cycle WAIT later (the ranging's
 * length), when the results can be read. */
static uint64_t ranging(uint64_t t, uint32_t near_mm, uint32_t far_mm, uint8_t cmd, uint64_t wait)
{
	srf08_set_targets(&s, near_mm, far_mm);
	command(t, 0xE0, cmd);
	return t + wait;
}

static void fresh(void)
{
	memset(&bus, 0, sizeof(bus));
	srf08_init(&s, SRF08_ADDR_DEFAULT, HZ, &bus);
}

/* --- tests ----------------------------------------------------------------- */

static void test_power_up(void)
{
	uint8_t b[4];

	fresh();
	eq(read_loc(10, 0xE0, 0, b, 4), 0, "power-up: E0 answers");
	eq(b[0], SRF08_REVISION, "location 0 reads the software revision");
	eq(b[1], 0, "light before any ranging");
	eq(b[2] << 8 | b[3], 0, "no echo before any ranging");
	eq(s.gain, 31, "max gain register at power-up");
	eq(s.range, 255, "range register at power-up");
	eq(ev_addr(10, 0xE2), 0, "E2 is not its address");
	ev_stop(10);
}

/* The specification's sequence: 0x51 to location 0, wait 65 ms, read 2,3. */
static void test_ranging_cm(void)
{
	uint64_t t0 = 1000;
	uint8_t b[2];

	fresh();
	srf08_set_targets(&s, 1234, 0);
	srf08_set_light(&s, 100);
	eq(command(t0, 0xE0, 0x51), 3, "S E0 00 51 P all acknowledged");
	eq(srf08_ranging_cycles(&s, 255), MS65, "default ranging: 65 ms");
	/* deaf while ranging: neither direction is acknowledged */
	eq(ev_addr(t0 + 1, 0xE0), 0, "write address NACKed just after the command");
	ev_stop(t0 + 1);
	eq(read_loc(t0 + MS65 / 2, 0xE0, 0, b, 1), -1, "polling mid-ranging: no ACK");
	eq(b[0], 0xff, "polling mid-ranging reads 255 (pull-up)");
	eq(echo(t0 + MS65 - 1, 0xE0, 0), -1, "one cycle before 65 ms: still deaf");
	eq(echo(t0 + MS65, 0xE0, 0), 123, "1234 mm at 65 ms: 123 cm");
	eq(echo(t0 + MS65, 0xE0, 1), 0, "no second echo");
	eq(read_loc(t0 + MS65, 0xE0, 0, b, 2), 0, "answers again");
	eq(b[0], SRF08_REVISION, "polling location 0 gives the revision again");
	eq(b[1], 100, "light sensor reading");
}

static void test_units(void)
{
	uint64_t t = 0;

	fresh();
	t = ranging(t, 1234, 0, 0x50, MS65);
	eq(echo(t, 0xE0, 0), 49, "0x50: 1234 mm = 48.6 in -> 49");
	t = ranging(t, 1234, 0, 0x52, MS65);
	eq(echo(t, 0xE0, 0), 7180, "0x52: 1234 mm -> 7180 us of flight at 343.75 m/s");
	t = ranging(t, 11008, 0, 0x52, MS65);
	eq(echo(t, 0xE0, 0), 64047, "11008 mm (the maximum) -> 64047 us, inside 65 ms");
	eq(srf08_convert(0x51, 4), 0, "4 mm rounds to 0 cm");
	eq(srf08_convert(0x51, 5), 1, "5 mm rounds to 1 cm");
	eq(srf08_convert(0x50, 254), 10, "254 mm = 10 in");
}

/* Range register: ((R x 43 mm) + 43 mm), with the document's examples. */
static void test_range_register(void)
{
	uint8_t v = 24;
	uint64_t t = 0, fast;

	eq(srf08_max_mm(0), 43, "range 0: 43 mm");
	eq(srf08_max_mm(1), 86, "range 1: 86 mm");
	eq(srf08_max_mm(24), 1075, "range 24 (0x18): about 1 m");
	eq(srf08_max_mm(140), 6063, "range 140 (0x8C): about 6 m");
	eq(srf08_max_mm(255), 11008, "range 255: 11008 mm");
	fresh();
	fast = srf08_ranging_cycles(&s, 24);
	eq(fast, 46800, "range 24: 6.35 ms of ranging (65 ms x 25/256)");
	eq(write_loc(t, 0xE0, 2, &v, 1), 3, "write range register");
	eq(s.range, 24, "range register holds 24");
	t = ranging(t, 1234, 0, 0x51, fast);
	eq(echo(t - 1, 0xE0, 0), -1, "still ranging just before 6.35 ms");
	eq(echo(t, 0xE0, 0), 0, "1234 mm is beyond a 1075 mm range: 0");
	t = ranging(t, 1075, 0, 0x51, fast);
	eq(echo(t, 0xE0, 0), 108, "1075 mm, at the edge of the range, is seen");
	t = ranging(t, 1076, 0, 0x51, fast);
	eq(echo(t, 0xE0, 0), 0, "1076 mm is not");
}

static void test_gain_and_increment(void)
{
	uint8_t gr[2] = { 0x10, 0x8C }, b[3];

	fresh();
	eq(write_loc(0, 0xE0, 1, gr, 2), 4, "gain and range in one write");
	eq(s.gain, 0x10, "gain register written");
	eq(s.range, 0x8C, "location counter moved on to the range register");
	eq(write_loc(0, 0xE0, 3, gr, 1), 3, "a write to location 3 is acknowledged");
	eq(s.gain, 0x10, "... and changes nothing");
	uint64_t t = ranging(0, 500, 0, 0x51, srf08_ranging_cycles(&s, 0x8C));
	eq(read_loc(t, 0xE0, 2, b, 1), 0, "read the high byte");
	eq(read_loc(t, 0xE0, -1, b + 1, 1), 0, "a new read continues at location 3");
	eq(b[0] << 8 | b[1], 50, "500 mm in two reads: 50 cm");
	eq(read_loc(t, 0xE0, 35, b, 3), 0, "read across the end");
	eq(b[1] | b[2], 0, "locations past 35 read 0");
}

static void test_two_echoes(void)
{
	uint64_t t = 0;

	fresh();
	t = ranging(t, 2000, 800, 0x51, MS65);
	eq(echo(t, 0xE0, 0), 80, "nearest echo first");
	eq(echo(t, 0xE0, 1), 200, "then the farther one");
	eq(echo(t, 0xE0, 2), 0, "then nothing");
	t = ranging(t, 800, 20000, 0x51, MS65);
	eq(echo(t, 0xE0, 1), 0, "a second echo beyond 11 m is not seen");
	t = ranging(t, 0, 0, 0x51, MS65);
	eq(echo(t, 0xE0, 0), 0, "nothing in front: 0, buffer cleared");
}

/* The light reading is made at the ping and shows once the ranging ends. */
static void test_light(void)
{
	uint8_t b;
	uint64_t t = 0;

	fresh();
	srf08_set_light(&s, 100);
	command(t, 0xE0, 0x51);
	srf08_set_light(&s, 200);	/* brighter during the ranging */
	t += MS65;
	eq(read_loc(t, 0xE0, 1, &b, 1), 0, "read location 1");
	eq(b, 100, "light as it was at the ping");
	command(t, 0xE0, 0x50);
	t += MS65;
	read_loc(t, 0xE0, 1, &b, 1);
	eq(b, 200, "next ranging: the new light");
}

/* A0, AA, A5, new address, each in its own write to location 0. */
static void test_address_change(void)
{
	static const uint8_t seq[4] = { 0xA0, 0xAA, 0xA5, 0xF2 };
	uint8_t b;

	fresh();
	for (int i = 0; i < 4; i++) {
		eq(command(0, 0xE0, seq[i]), 3, "sequence byte acknowledged");
	}
	eq(s.addr8, 0xF2, "address now F2 (the document's example)");
	eq(read_loc(0, 0xE0, 0, &b, 1), -1, "E0 no longer answers");
	eq(read_loc(0, 0xF2, 0, &b, 1), 0, "F2 answers");
	eq(b, SRF08_REVISION, "at F2: the revision");
	eq(s.busy_until, 0, "the sequence starts no ranging");

	/* a command in the middle breaks it (0x51 ranges as usual) */
	fresh();
	command(0, 0xE0, 0xA0);
	command(0, 0xE0, 0xAA);
	command(0, 0xE0, 0x51);
	command(MS65, 0xE0, 0xA5);
	command(MS65, 0xE0, 0xF2);
	eq(s.addr8, 0xE0, "interrupted sequence: address kept");

	/* all four in one write: locations 0, 1, 2, 3 */
	fresh();
	eq(write_loc(0, 0xE0, 0, seq, 4), 6, "one write of A0 AA A5 F2");
	eq(s.addr8, 0xE0, "one write is not the sequence: address kept");
	eq(s.gain, 0xAA, "AA went to the gain register");
	eq(s.range, 0xA5, "A5 went to the range register");

	/* an address outside E0..FE */
	fresh();
	for (int i = 0; i < 3; i++) {
		command(0, 0xE0, seq[i]);
	}
	command(0, 0xE0, 0x70);
	eq(s.addr8, 0xE0, "0x70 is not an SRF08 address: kept");
	command(0, 0xE0, 0xF3);
	eq(s.addr8, 0xE0, "odd addresses are refused");
	for (int i = 0; i < 3; i++) {
		command(0, 0xE0, seq[i]);
	}
	command(0, 0xE0, 0xFE);
	eq(s.addr8, 0xFE, "FE, the last of the 16");
}

static void test_general_call_and_deaf_transfer(void)
{
	uint8_t two[2] = { 0x51, 0x52 };

	fresh();
	srf08_set_targets(&s, 1000, 0);
	eq(command(0, 0x00, 0x51), 3, "broadcast address 0 takes a ranging command");
	eq(ev_addr(1, 0xE1), 0, "and it is ranging");
	ev_stop(1);
	eq(echo(MS65, 0xE0, 0), 100, "result read at its own address");
	eq(ev_addr(MS65, 0x01), 0, "address 0 is not answered for reading");
	ev_stop(MS65);
	fresh();
	eq(write_loc(0, 0xE0, 0, two, 2), 3, "the byte after a command is not acknowledged");
	eq(s.rangings, 1, "one ranging");
}

/* ANN mode: 32 slots of 2048 us (352 mm) in locations 4..35. */
static void test_ann(void)
{
	uint8_t b[36];
	int nonzero = 0;

	fresh();
	uint64_t t = ranging(0, 3000, 0, 0x54, MS65);
	eq(read_loc(t, 0xE0, 0, b, 36), 0, "read all 36 locations");
	eq(b[2] << 8 | b[3], 300, "ANN cm: locations 2,3 as in ranging mode");
	eq(b[12] != 0, 1, "3 m: location 12 (the document's example)");
	for (int i = 4; i < 36; i++) {
		nonzero += b[i] != 0;
	}
	eq(nonzero, 1, "no other slot set");
	t = ranging(t, 100, 400, 0x53, MS65);
	read_loc(t, 0xE0, 0, b, 36);
	eq(b[2] << 8 | b[3], 4, "ANN inches: 100 mm -> 4");
	eq(b[4] != 0 && b[5] != 0 && b[6] == 0, 1, "0-352 mm: location 4, 353-705: 5");
}

int main(void)
{
	test_power_up();
	test_ranging_cm();
	test_units();
	test_range_register();
	test_gain_and_increment();
	test_two_echoes();
	test_light();
	test_address_change();
	test_general_call_and_deaf_transfer();
	test_ann();
	printf("srf08: %d passed, %d failed\n", passed, failed);
	return failed != 0;
}
