/*
 * Harness fuzz-parse: the serial gateway's parser (serialgate/sg_parse.c)
 * with its executor over the unit tests' fakes (tests/unit/fakes.c: a bus
 * with an EEPROM at A0, the test driver "fake" as the local register map).
 * The input is the bytes the UART hands over, lost-run markers included;
 * fuzz_gate.c says what is checked.
 */
#include <string.h>

#include "fakes.h"
#include "fuzz.h"

static struct {
	uint8_t eeprom[sizeof eeprom];
	reg_status_t status;
} before;

void fuzz_gate_boot(void)
{
	regmap_init();
}

void fuzz_gate_save(void)
{
	memcpy(before.eeprom, eeprom, sizeof eeprom);
	before.status = regmap_status();
}

int fuzz_gate_unchanged(void)
{
	return memcmp(before.eeprom, eeprom, sizeof eeprom) == 0 && before.status == regmap_status();
}

void fuzz_gate_after_line(void)
{
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	fuzz_gate_run(data, size);
	return 0;
}
