/*
 * The board map: what the host needs to know of a board, written as JSON
 * from the very definitions the firmware is built from (boards/<board>/,
 * the driver headers, the status and error enums). Host-compiled once per
 * board by `make map`, which writes host/orfa/maps/<board>.json; the Python
 * package, the tests, the benchmark and the docs' tables read that file, and
 * tests/host/test_boardmap.py fails when it is not what this program writes.
 *
 * Built with the board's include path and, as for the firmware,
 * -DORFA_DRIVER_LIST="X(gpio) X(spi) ..." plus the board.mk facts the C
 * headers do not hold: -DMAP_AVRDUDE_PART="m32" -DMAP_FUSES="lfuse:0xff ...".
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "board.h"
#include "drivers/drivers.h"
#include "firmware/board_fn.h"
#include "firmware/i2c_addr.h"
#include "firmware/sys.h"
#include "serialgate/sg_exec.h"
#include "serialgate/sg_parse.h"

#ifndef MAP_AVRDUDE_PART
#error "MAP_AVRDUDE_PART (board.mk BOARD_AVRDUDE_PART) is not given"
#endif
#ifndef MAP_FUSES
#error "MAP_FUSES (board.mk BOARD_FUSES) is not given"
#endif

static const char gpio_ports[] = {
#define MAP_PORT(letter) letter,
	BOARD_GPIO_PORTS(MAP_PORT)
#undef MAP_PORT
	'\0'
};

/* The pin functions' names, by board_fn_t. */
static const char *const pin_functions[] = {
#define MAP_FN(name) [BF_##name] = #name,
	BOARD_FN_LIST(MAP_FN)
#undef MAP_FN
};

static unsigned next_start;
static int first_driver = 1;

/* One register name, or one per GPIO port ("VALUE_%c"). */
static void print_regs(const char *name, int per_port, int *first, unsigned *n)
{
	const char *p;

	for (p = per_port ? gpio_ports : " "; *p != '\0'; p++) {
		printf("%s\"", *first ? "" : ", ");
		if (per_port) {
			printf(name, *p);
		} else {
			fputs(name, stdout);
		}
		putchar('"');
		*first = 0;
		(*n)++;
	}
}

static void print_driver(const char *name, unsigned uid, unsigned major, unsigned minor,
			 unsigned nregs)
{
	printf("%s\n    {\"name\": \"%s\", \"uid\": %u, \"major\": %u, \"minor\": %u, "
	       "\"start\": %u, \"count\": %u,\n     \"registers\": [",
	       first_driver ? "" : ",", name, uid, major, minor, next_start, nregs);
	first_driver = 0;
	next_start += nregs;
}

static void end_driver(const char *name, unsigned nregs, unsigned named)
{
	printf("]}");
	if (named != nregs) {
		fprintf(stderr, "mapgen: driver %s has %u registers but names %u\n",
			name, nregs, named);
		exit(1);
	}
}

#define MAP_DRIVER(name) do { \
	int first_ = 1; \
	unsigned named_ = 0; \
	print_driver(#name, DRV_##name##_UID, DRV_##name##_MAJOR, DRV_##name##_MINOR, \
		     DRV_##name##_NREGS); \
	DRV_##name##_REGS(MAP_REG_OF) \
	end_driver(#name, DRV_##name##_NREGS, named_); \
} while (0);
#define MAP_REG_OF(rname, per_port) print_regs(rname, per_port, &first_, &named_);

/* "lfuse:0xff hfuse:0xd9" as JSON members "lfuse": 255, "hfuse": 217 */
static void print_fuses(const char *spec)
{
	char buf[128];
	char *tok;
	int first = 1;

	snprintf(buf, sizeof buf, "%s", spec);
	for (tok = strtok(buf, " "); tok != NULL; tok = strtok(NULL, " ")) {
		char *colon = strchr(tok, ':');
		if (colon == NULL) {
			fprintf(stderr, "mapgen: fuse %s is not name:value\n", tok);
			exit(1);
		}
		*colon = '\0';
		printf("%s\"%s\": %lu", first ? "" : ", ", tok, strtoul(colon + 1, NULL, 0));
		first = 0;
	}
}

int main(void)
{
	int first = 1;

	printf("{\n  \"schema\": 1,\n");
	printf("  \"board\": \"%s\",\n  \"name\": \"%s\",\n  \"mcu\": \"%s\",\n  \"f_cpu\": %lu,\n",
	       BOARD_ID, BOARD_NAME, BOARD_MCU_NAME, (unsigned long)BOARD_CLOCK_HZ);
	printf("  \"avrdude\": {\"part\": \"%s\", \"fuses\": {", MAP_AVRDUDE_PART);
	print_fuses(MAP_FUSES);
	printf("}},\n");
	printf("  \"uart\": %d,\n  \"gpio_ports\": \"%s\",\n  \"adc_port\": \"%c\",\n",
	       BOARD_UART, gpio_ports, BOARD_ADC_PORT);
	printf("  \"servo_channels\": %d,\n", BOARD_SERVO_CHANNELS);
	printf("  \"local_address\": %d,\n", SG_LOCAL_DEFAULT);
	printf("  \"bus_address\": {\"min\": %d, \"max\": %d},\n", I2C_ADDR_MIN, I2C_ADDR_MAX);
	printf("  \"limits\": {\"request_chars\": %d, \"reply_chars\": %d, "
	       "\"servo_min_us\": %d, \"servo_max_us\": %d, \"servo_triples\": %d, "
	       "\"spi_channels\": %d, \"spi_bytes\": %d, \"read_bytes\": %d, "
	       "\"failsafe_max_ms\": %u},\n",
	       SG_LINE_MAX, SG_REPLY_MAX, SERVO_MIN_US, SERVO_MAX_US, SERVO_MAX_TRIPLES,
	       SPI_CHANNELS, SPI_BUF, REGMAP_READ_MAX, SYS_FAILSAFE_MAX_MS);

	printf("  \"pin_functions\": [");
	for (size_t i = 0; i < sizeof pin_functions / sizeof pin_functions[0]; i++) {
		printf("%s\"%s\"", i ? ", " : "", pin_functions[i]);
	}
	printf("],\n");
	/* BF_##fn: a function the list does not have does not compile. */
	printf("  \"pins\": [");
#define MAP_PIN(port, bit, fn, index) \
	printf("%s\n    {\"port\": \"%c\", \"bit\": %d, \"function\": \"%s\", \"index\": %d}", \
	       first ? "" : ",", port, bit, pin_functions[BF_##fn], index); \
	first = 0;
	BOARD_PINS(MAP_PIN)
#undef MAP_PIN
	printf("\n  ],\n");

	/* The register order of firmware/regmap.c: introspection, the board's
	 * drivers, sys last. */
	printf("  \"drivers\": [");
	MAP_DRIVER(intro)
#define X(name) MAP_DRIVER(name)
	ORFA_DRIVER_LIST
#undef X
	MAP_DRIVER(sys)
	printf("\n  ],\n");

	printf("  \"reset_causes\": {\"power\": %d, \"external\": %d, \"brownout\": %d, "
	       "\"watchdog\": %d, \"jtag\": %d},\n",
	       SYS_RESET_POWER, SYS_RESET_EXTERNAL, SYS_RESET_BROWNOUT, SYS_RESET_WATCHDOG,
	       SYS_RESET_JTAG);

	/* The status values, then the protocol's errors: the same shape. */
#define MAP_CODE(name, code, text) \
	printf("%s\n    {\"code\": %d, \"name\": \"%s\", \"text\": \"%s\"}", \
	       first ? "" : ",", code, #name, text); \
	first = 0;
	first = 1;
	printf("  \"status\": [");
	REG_STATUS_LIST(MAP_CODE)
	printf("\n  ],\n");
	first = 1;
	printf("  \"errors\": [");
	SG_ERR_LIST(MAP_CODE)
	printf("\n  ]\n}\n");
#undef MAP_CODE
	return 0;
}
