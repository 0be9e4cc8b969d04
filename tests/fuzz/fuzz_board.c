/*
 * A board's real drivers over tests/unit/hw_fakes.c, for the fuzz harnesses:
 * power-on, the check helpers the shared unit-test code reports through
 * (abort instead of counting), and the pins no driver may move.
 */
#include <string.h>

#include "drv_test.h"
#include "fuzz.h"

void boot(void)
{
	hw_fakes_reset();
	pins_init();
	regmap_init();
}

void check_at(const char *file, int line, int ok, const char *what)
{
	if (!ok) {
		fuzz_fail(file, line, "%s", what);
	}
}

void check_eq_at(const char *file, int line, long got, long want, const char *what)
{
	if (got != want) {
		fuzz_fail(file, line, "%s = 0x%lX, want 0x%lX", what, got, want);
	}
}

uint8_t fuzz_board_nregs(void)
{
	uint8_t rec[REGMAP_RECORD_LEN];
	regmap_driver_record(regmap_driver_count(), rec, sizeof rec);
	return (uint8_t)(rec[4] + rec[5]);
}

static struct {
	uint8_t mask[BOARD_NPORTS];   /* lines of fixed functions */
	uint8_t out[BOARD_NPORTS], ddr[BOARD_NPORTS];
	uint8_t owner[BOARD_NPORTS * 8];
} fixed;

static int is_fixed(pin_owner_t o)
{
	return o == PIN_UART || o == PIN_TWI || o == PIN_SPI || o == PIN_SERVO_CLK;
}

void fuzz_board_fixed_save(void)
{
	memset(fixed.mask, 0, sizeof fixed.mask);
	for (uint8_t pin = 0; pin < BOARD_NPORTS * 8; pin++) {
		fixed.owner[pin] = (uint8_t)pins_owner(pin);
		if (is_fixed(pins_owner(pin))) {
			fixed.mask[PIN_PORT(pin)] |= PIN_MASK(pin);
		}
	}
	memcpy(fixed.out, port_out, sizeof fixed.out);
	memcpy(fixed.ddr, port_ddr, sizeof fixed.ddr);
}

void fuzz_board_fixed_check(void)
{
	for (uint8_t p = 0; p < BOARD_NPORTS; p++) {
		uint8_t m = fixed.mask[p];
		FUZZ_REQUIRE(((port_out[p] ^ fixed.out[p]) & m) == 0 &&
			     ((port_ddr[p] ^ fixed.ddr[p]) & m) == 0,
			     "port %c: a fixed function's line moved (mask %02X, PORT %02X->%02X, "
			     "DDR %02X->%02X)", 'A' + p, m, fixed.out[p], port_out[p], fixed.ddr[p],
			     port_ddr[p]);
	}
	for (uint8_t pin = 0; pin < BOARD_NPORTS * 8; pin++) {
		if (is_fixed((pin_owner_t)fixed.owner[pin])) {
			FUZZ_REQUIRE(pins_owner(pin) == fixed.owner[pin],
				     "pin %c%u of a fixed function (%u) now owned by %u",
				     'A' + PIN_PORT(pin), pin & 7, fixed.owner[pin], pins_owner(pin));
		}
	}
}
