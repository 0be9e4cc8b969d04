/*
 * Harness fuzz-regmap-<board>: register operations straight into the
 * register map (firmware/regmap.c) and the board's real drivers over
 * tests/unit/hw_fakes.c. The input is a list of operations:
 *   op % 5 == 0  select [reg]              (mostly mapped registers)
 *   op % 5 == 1  write  [len][data...]     (len % 70)
 *   op % 5 == 2  read   [n][max]           (n bytes, max per driver answer)
 *   op % 5 == 3  check  [len][data...]     (regmap_check on every prefix)
 *   op % 5 == 4  inputs [what][value]      (pin levels, ADC values, SPI bytes)
 * Checked (regmap.h, docs/registers.md):
 *  - select is true exactly for mapped registers; after an unmapped one
 *    writes and reads are refused and the status says 08;
 *  - the status register gives the last write's result; a read sets it to
 *    OK or 05 (06 for introspection past its end); reading it leaves it;
 *  - a driver answers at most `max` bytes and writes nothing beyond them;
 *    a read of any register but introspection gives the same bytes twice;
 *  - regmap_check changes nothing; a write it refuses at some prefix is
 *    rejected whole;
 *  - a rejected write changes nothing: pins, owners, hardware records and
 *    the driver's readable registers (introspection's cursor aside);
 *  - no write moves the lines of fixed functions (UART, TWI, SPI bus).
 */
#include <stdio.h>
#include <string.h>

#include "drv_test.h"
#include "fuzz.h"

#define LEN_MAX 70
#define CANARY 0xA5
#define REGS_MAX 32  /* registers a board maps, at most (M32-D: 0x14) */

static fuzz_input_t in;

static uint8_t canary[64 + 16];

static struct {
	uint8_t nregs;
	uint8_t reg;       /* selected register */
	int selected;      /* a mapped register is selected */
} m;

/* Pins, owners and hardware records: what a check must not change. */
typedef struct {
	uint8_t out[BOARD_NPORTS], ddr[BOARD_NPORTS];
	uint8_t owner[BOARD_NPORTS * 8];
	hw_rec_t hw;
	reg_status_t status;
} hw_snap_t;

/* ... and every readable register's first 64 bytes (not introspection,
 * whose reads move its cursor, nor status). */
typedef struct {
	hw_snap_t hw;
	uint8_t readable[REGS_MAX];
	uint8_t regs[REGS_MAX][64];
} reg_snap_t;

static void hw_snap(hw_snap_t *s)
{
	memset(s, 0, sizeof *s);
	memcpy(s->out, port_out, sizeof s->out);
	memcpy(s->ddr, port_ddr, sizeof s->ddr);
	for (uint8_t pin = 0; pin < BOARD_NPORTS * 8; pin++) {
		s->owner[pin] = (uint8_t)pins_owner(pin);
	}
	memcpy(&s->hw, &hw, sizeof hw);
	s->status = regmap_status();
}

/* A read of n bytes of the selected register, the driver asked for at most
 * `max` at a time, as xact.c asks it. Returns the bytes read (0: refused).
 * `checked`: each answer in a buffer of its own, checked for bytes written
 * beyond it. */
static unsigned read_reg(uint8_t *dst, unsigned n, uint8_t max, int checked)
{
	unsigned got = 0;
	uint8_t chunk[64 + 16];

	regmap_read_start();
	while (got < n) {
		uint8_t ask = (uint8_t)(n - got < max ? n - got : max);
		uint8_t *to = checked ? chunk : dst + got;
		if (checked) {
			memcpy(chunk, canary, sizeof chunk);
		}
		uint8_t k = regmap_read(to, ask);
		FUZZ_REQUIRE(k <= ask, "register %02X answered %u bytes for %u", m.reg, k, ask);
		if (k == 0) {
			return 0;
		}
		if (checked) {
			FUZZ_REQUIRE(memcmp(chunk + ask, canary, sizeof chunk - ask) == 0,
				     "register %02X wrote beyond an answer of at most %u", m.reg, ask);
			memcpy(dst + got, chunk, k);
		}
		got += k;
	}
	return got;
}

static void reselect(reg_status_t status)
{
	regmap_select(m.selected ? m.reg : 0xFF);
	regmap_set_status(status);
}

/* The registers of the driver that maps `reg` (introspection and status
 * aside): a rejected write could only change these, or pins (hw_snap). */
static void driver_regs(uint8_t reg, uint8_t *first, uint8_t *end)
{
	*first = *end = 2;
	for (uint8_t d = 1; d <= regmap_driver_count(); d++) {
		uint8_t rec[REGMAP_RECORD_LEN];
		regmap_driver_record(d, rec, sizeof rec);
		if (reg >= rec[4] && reg < rec[4] + rec[5]) {
			*first = rec[4] < 2 ? 2 : rec[4];
			*end = (uint8_t)(rec[4] + rec[5]);
			return;
		}
	}
}

static void snap(reg_snap_t *s)
{
	uint8_t first, end;
	hw_snap(&s->hw);
	driver_regs(m.reg, &first, &end);
	for (uint8_t reg = first; reg < end && m.selected; reg++) {
		/* a driver's first answer of up to 64 bytes is all it holds */
		regmap_select(reg);
		regmap_read_start();
		memset(s->regs[reg], 0, 64);
		s->readable[reg] = regmap_read(s->regs[reg], 64) != 0;
	}
	reselect(s->hw.status);
}

static void same(const reg_snap_t *before, const char *what)
{
	static reg_snap_t now;
	uint8_t first, end;
	snap(&now);
	FUZZ_REQUIRE(memcmp(&now.hw, &before->hw, sizeof now.hw) == 0,
		     "%s changed pins or hardware", what);
	driver_regs(m.reg, &first, &end);
	for (uint8_t reg = first; reg < end && m.selected; reg++) {
		FUZZ_REQUIRE(now.readable[reg] == before->readable[reg] &&
			     memcmp(now.regs[reg], before->regs[reg], 64) == 0,
			     "%s changed register %02X", what, reg);
	}
}

static void op_select(void)
{
	uint8_t r = fuzz_byte(&in);
	uint8_t reg = (r & 0x80) ? r : (uint8_t)(r % (m.nregs + 1));
	bool ok = regmap_select(reg);
	FUZZ_REQUIRE(ok == (reg < m.nregs), "select %02X gave %d (%u registers)", reg, ok, m.nregs);
	if (!ok) {
		FUZZ_REQUIRE(regmap_status() == REG_NO_REGISTER, "unmapped %02X: status %02X", reg,
			     regmap_status());
	}
	m.reg = reg;
	m.selected = ok;
}

static uint8_t take_data(uint8_t *data)
{
	uint8_t len = (uint8_t)(fuzz_byte(&in) % LEN_MAX);
	for (uint8_t i = 0; i < len; i++) {
		data[i] = fuzz_byte(&in);
	}
	return len;
}

/* The first prefix length regmap_check refuses, 0 if none. */
static uint8_t refused_at(const uint8_t *data, uint8_t len)
{
	hw_snap_t a, b;
	uint8_t at = 0;
	hw_snap(&a);
	for (uint8_t k = 1; k <= len && !at; k++) {
		if (regmap_check(data, k) != REG_OK) {
			at = k;
		}
	}
	hw_snap(&b);
	FUZZ_REQUIRE(memcmp(&a, &b, sizeof a) == 0, "regmap_check changed something (register %02X)",
		     m.reg);
	return at;
}

static void op_write(void)
{
	static reg_snap_t before;
	uint8_t data[LEN_MAX];
	uint8_t len = take_data(data);
	uint8_t at = refused_at(data, len);

	snap(&before);
	reg_status_t st = regmap_write(data, len);
	FUZZ_REQUIRE(regmap_status() == st, "write result %02X, status %02X", st, regmap_status());
	if (!m.selected) {
		FUZZ_REQUIRE(st == REG_NO_REGISTER, "write with nothing selected: %02X", st);
	} else if (m.reg == REGMAP_STATUS_REG) {
		FUZZ_REQUIRE(st == REG_NOT_WRITABLE, "write to the status register: %02X", st);
	}
	FUZZ_REQUIRE(!at || st != REG_OK, "register %02X: check refused byte %u, the write of %u "
		     "bytes was taken", m.reg, at, len);
	if (st != REG_OK) {
		before.hw.status = st;
		char what[80];
		snprintf(what, sizeof what, "a rejected write (%02X) to register %02X", st, m.reg);
		same(&before, what);
	}
	fuzz_board_fixed_check();
}

static void op_check(void)
{
	uint8_t data[LEN_MAX];
	uint8_t len = take_data(data);
	(void)refused_at(data, len);
}

static void op_read(void)
{
	uint8_t a[LEN_MAX + 64], b[LEN_MAX + 64];
	unsigned n = 1 + fuzz_byte(&in) % LEN_MAX;
	uint8_t max = (uint8_t)(1 + fuzz_byte(&in) % 64);
	reg_status_t st0 = regmap_status();

	unsigned got = read_reg(a, n, max, 1);
	reg_status_t st = regmap_status();
	if (!m.selected) {
		FUZZ_REQUIRE(got == 0 && st == REG_NO_REGISTER, "read with nothing selected");
		return;
	}
	if (m.reg == REGMAP_STATUS_REG) {
		FUZZ_REQUIRE(got == n && st == st0, "status read changed the status");
		for (unsigned i = 0; i < n; i++) {
			FUZZ_REQUIRE(a[i] == st0, "status read gave %02X, status %02X", a[i], st0);
		}
		return;
	}
	if (got == 0) {
		FUZZ_REQUIRE(st == REG_NOT_READABLE, "refused read of %02X: status %02X", m.reg, st);
		return;
	}
	FUZZ_REQUIRE(st == REG_OK || (m.reg == REGMAP_INTRO_REG && st == REG_READ_WRAPPED),
		     "read of %02X: status %02X", m.reg, st);
	if (m.reg != REGMAP_INTRO_REG) {
		unsigned again = read_reg(b, n, max, 0);
		FUZZ_REQUIRE(again == got && memcmp(a, b, got) == 0,
			     "register %02X read twice gave different bytes", m.reg);
	}
}

static void op_inputs(void)
{
	uint8_t what = fuzz_byte(&in), v = fuzz_byte(&in);
	switch (what % 3) {
	case 0:
		port_ext[(what >> 2) % BOARD_NPORTS] = v;
		break;
	case 1:
		adc_in[(what >> 2) & 7] = (uint16_t)(v << 2 | (what >> 5));
		break;
	default: {
		uint8_t miso[8];
		for (unsigned i = 0; i < sizeof miso; i++) {
			miso[i] = (uint8_t)(v + 17 * i);
		}
		spi_script(miso, (what >> 2) % (sizeof miso + 1));
		break;
	}
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	in = (fuzz_input_t){ data, size };
	memset(canary, CANARY, sizeof canary);
	boot();
	fuzz_board_fixed_save();
	m.nregs = fuzz_board_nregs();
	FUZZ_REQUIRE(m.nregs <= REGS_MAX, "%u registers", m.nregs);
	m.reg = REGMAP_INTRO_REG;
	m.selected = 1;
	while (in.left) {
		switch (fuzz_byte(&in) % 5) {
		case 0:
			op_select();
			break;
		case 1:
			op_write();
			break;
		case 2:
			op_read();
			break;
		case 3:
			op_check();
			break;
		default:
			op_inputs();
			break;
		}
		hw_log_clear();
	}
	fuzz_board_fixed_check();
	return 0;
}
