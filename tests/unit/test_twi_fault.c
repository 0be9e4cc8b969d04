/*
 * The simulator's faults in the middle of a byte (sim/periph/twi_fault.c):
 * which byte and bit a fault hits, counted from the START after arming;
 * the arguments refused. (What the lines then carry is the bus's:
 * tests/sim/test_bus_faults_midbyte.py.)
 */
#include <stdio.h>
#include <string.h>

#include "periph/twi_fault.h"

#include "check.h"

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
	/* a transaction that ends before the byte: dropped at its STOP */
	twi_fault_arm(&f, TWI_FAULT_START, 5, 1);
	CHECK(!twi_fault_on_stop(&f) && f.kind == TWI_FAULT_START, "a STOP before the count");
	twi_fault_on_start(&f);
	twi_fault_byte_done(&f);
	CHECK(twi_fault_on_stop(&f) && f.kind == TWI_FAULT_NONE, "missed at the STOP");
	CHECK(!twi_fault_on_stop(&f), "once");
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
	test_counting();
	test_arguments();
	printf("twi fault: %d passed, %d failed\n", checks - failures, failures);
	return failures != 0;
}
