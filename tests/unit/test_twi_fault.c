/*
 * The simulator's faults in the middle of a byte (sim/periph/twi_fault.c):
 * which byte and bit a fault hits, counted from the START after arming;
 * what the devices read when the master loses arbitration, and when it
 * does not lose; the arguments refused.
 */
#include <stdio.h>
#include <string.h>

#include "periph/twi_fault.h"

#include "check.h"

static void test_arb_sent(void)
{
	int lost;

	/* 0x10 = 0001 0000: bit 3 is the first 1; the master lets SDA go
	 * after it: the devices read 000 0 1111 */
	CHECK(twi_fault_arb_sent(0x10, 3, &lost) == 0x0F && lost, "0x10 bit 3");
	/* a 0 bit: the master pulls low too, nothing lost, nothing changed */
	CHECK(twi_fault_arb_sent(0x10, 0, &lost) == 0x10 && !lost, "0x10 bit 0");
	/* the last bit: only it changes */
	CHECK(twi_fault_arb_sent(0xDD, 7, &lost) == 0xDC && lost, "0xDD bit 7");
	/* the first bit: all after it released */
	CHECK(twi_fault_arb_sent(0x80, 0, &lost) == 0x7F && lost, "0x80 bit 0");
	/* the acknowledge bit belongs to the receiver */
	CHECK(twi_fault_arb_sent(0xFF, 8, &lost) == 0xFF && !lost, "ack bit");
	/* every byte and bit: lost exactly where a 1 was sent; the bits
	 * before it as sent, it 0, after it 1 */
	for (unsigned v = 0; v < 256; v++) {
		for (unsigned bit = 0; bit < 8; bit++) {
			uint8_t m = (uint8_t)(0x80u >> bit), got = twi_fault_arb_sent((uint8_t)v, bit, &lost);
			uint8_t before = (uint8_t)~(2 * m - 1);

			CHECK(lost == !!(v & m), "%02X bit %u lost %d", v, bit, lost);
			if (lost) {
				CHECK((got & before) == (v & before) && !(got & m) &&
				      (got & (m - 1)) == m - 1, "%02X bit %u read %02X", v, bit, got);
			} else {
				CHECK(got == v, "%02X bit %u read %02X", v, bit, got);
			}
		}
	}
	CHECK(twi_fault_arb_read(0x05, 5) == 0x01 && twi_fault_arb_read(0x05, 0) == 0x05,
	      "a device's byte: the bit read as 0");
}

static void test_counting(void)
{
	twi_fault_t f;
	unsigned bit = 99;

	twi_fault_arm(&f, TWI_FAULT_ARB, 2, 5);
	/* nothing counts before the START (a transfer under way when armed) */
	CHECK(twi_fault_here(&f, &bit) == TWI_FAULT_NONE, "before the START");
	twi_fault_byte_done(&f);
	twi_fault_byte_done(&f);
	twi_fault_on_start(&f);
	CHECK(twi_fault_here(&f, &bit) == TWI_FAULT_NONE, "byte 0");
	twi_fault_byte_done(&f);
	/* a repeated START does not begin the count again */
	twi_fault_on_start(&f);
	CHECK(twi_fault_here(&f, &bit) == TWI_FAULT_NONE, "byte 1");
	twi_fault_byte_done(&f);
	CHECK(twi_fault_here(&f, &bit) == TWI_FAULT_ARB && bit == 5, "byte 2");
	CHECK(twi_fault_here(&f, &bit) == TWI_FAULT_ARB, "asked again, same byte");
	twi_fault_byte_done(&f);
	/* fired once: gone */
	CHECK(f.kind == TWI_FAULT_NONE && twi_fault_here(&f, &bit) == TWI_FAULT_NONE, "spent");
	twi_fault_on_start(&f);
	for (int i = 0; i < 5; i++) {
		CHECK(twi_fault_here(&f, &bit) == TWI_FAULT_NONE, "disarmed, byte %d", i);
		twi_fault_byte_done(&f);
	}
	/* byte 0: the START's own address */
	twi_fault_arm(&f, TWI_FAULT_STOP, 0, 8);
	twi_fault_on_start(&f);
	CHECK(twi_fault_here(&f, &bit) == TWI_FAULT_STOP && bit == 8, "byte 0");
}

static void test_arguments(void)
{
	twi_fault_t f;
	char buf[40];

	twi_fault_arm(&f, TWI_FAULT_NONE, 0, 0);
	CHECK(twi_fault_arm(&f, TWI_FAULT_ARB, 0, 9) < 0, "arb bit 9");
	CHECK(twi_fault_arm(&f, TWI_FAULT_ARB, 256, 0) < 0, "byte 256");
	CHECK(twi_fault_arm(&f, TWI_FAULT_START, 1, 0) < 0, "a glitch in bit 0 is legal");
	CHECK(f.kind == TWI_FAULT_NONE, "a refused one arms nothing");
	CHECK(twi_fault_arm(&f, TWI_FAULT_ARB, 255, 0) == 0, "arb 255 0");
	CHECK(!strcmp(twi_fault_describe(&f, buf, sizeof buf), "arb 255 0"), "%s", buf);
	CHECK(twi_fault_arm(&f, TWI_FAULT_STOP, 3, 8) == 0, "glitch stop 3 8");
	CHECK(!strcmp(twi_fault_describe(&f, buf, sizeof buf), "glitch stop 3 8"), "%s", buf);
	twi_fault_arm(&f, TWI_FAULT_NONE, 0, 0);
	CHECK(!strcmp(twi_fault_describe(&f, buf, sizeof buf), "none"), "%s", buf);
}

int main(void)
{
	test_arb_sent();
	test_counting();
	test_arguments();
	printf("twi fault: %d passed, %d failed\n", checks - failures, failures);
	return failures != 0;
}
