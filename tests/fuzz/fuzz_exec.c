/*
 * Harness fuzz-exec-<board>: the serial gateway (parser and executor) over
 * one board's real drivers, register map and pin table, compiled for the
 * host over tests/unit/hw_fakes.c, with the unit tests' fake bus
 * (tests/unit/fakes.c). Requests to the local address reach the drivers.
 * Besides fuzz_gate.c's checks of every reply: a request that is not run
 * changes no pin, hardware record or status, and no request moves the
 * lines of the UART, the TWI, the SPI bus or the servo counters.
 */
#include <string.h>

#include "drv_test.h"
#include "fakes.h"
#include "fuzz.h"

static struct {
	uint8_t eeprom[sizeof eeprom];
	reg_status_t status;
	uint8_t out[BOARD_NPORTS], ddr[BOARD_NPORTS];
	uint8_t owner[BOARD_NPORTS * 8];
	hw_rec_t hw;
} before;

void fuzz_gate_boot(void)
{
	boot();
	fuzz_board_fixed_save();
}

void fuzz_gate_save(void)
{
	memcpy(before.eeprom, eeprom, sizeof eeprom);
	before.status = regmap_status();
	memcpy(before.out, port_out, sizeof before.out);
	memcpy(before.ddr, port_ddr, sizeof before.ddr);
	for (uint8_t pin = 0; pin < BOARD_NPORTS * 8; pin++) {
		before.owner[pin] = (uint8_t)pins_owner(pin);
	}
	memcpy(&before.hw, &hw, sizeof hw);
}

int fuzz_gate_unchanged(void)
{
	int same = memcmp(before.eeprom, eeprom, sizeof eeprom) == 0 &&
		   before.status == regmap_status() &&
		   memcmp(before.out, port_out, sizeof before.out) == 0 &&
		   memcmp(before.ddr, port_ddr, sizeof before.ddr) == 0 &&
		   memcmp(&before.hw, &hw, sizeof hw) == 0;
	for (uint8_t pin = 0; pin < BOARD_NPORTS * 8; pin++) {
		same &= before.owner[pin] == (uint8_t)pins_owner(pin);
	}
	return same;
}

void fuzz_gate_after_line(void)
{
	fuzz_board_fixed_check();
	hw_log_clear();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	fuzz_gate_run(data, size);
	return 0;
}
