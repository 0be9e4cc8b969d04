#include "firmware/regmap.h"

#include "drivers/drivers.h"
#include "firmware/sys.h"

/* Start registers, computed by the compiler: each driver starts right after
 * the last register of the one before it. */
enum {
	REGMAP_LAST_intro = DRV_intro_NREGS - 1,
#define X(name) \
	REGMAP_START_##name, \
	REGMAP_LAST_##name = REGMAP_START_##name + DRV_##name##_NREGS - 1,
	ORFA_DRIVER_LIST
#undef X
	/* sys always last: appending it moved no other register */
	REGMAP_START_sys,
	REGMAP_LAST_sys = REGMAP_START_sys + DRV_sys_NREGS - 1,
	REGMAP_END
};

_Static_assert(REGMAP_END <= 0x100, "registers must fit in one byte");

/* One flat table in flash: function pointers read straight from it (a
 * pointer to a descriptor that itself lives in flash is the double
 * indirection avr-gcc 5.4 gets wrong at -O2). */
typedef struct {
	void (*init)(void);
	reg_status_t (*write)(uint8_t reg, const uint8_t *data, uint8_t len);
	uint8_t (*read)(uint8_t reg, uint8_t *dst, uint8_t max);
	reg_status_t (*check)(uint8_t reg, const uint8_t *data, uint8_t len);
} regmap_entry_t;

static const ORFA_FLASH regmap_entry_t regmap_table[] = {
	{ drv_intro_init, drv_intro_write, drv_intro_read, drv_intro_check },
#define X(name) { drv_##name##_init, drv_##name##_write, drv_##name##_read, drv_##name##_check },
	ORFA_DRIVER_LIST
#undef X
	{ drv_sys_init, drv_sys_write, drv_sys_read, drv_sys_check },
};

#define REGMAP_NDRIVERS ((uint8_t)(sizeof regmap_table / sizeof regmap_table[0]))

/* Each driver's row in regmap_table. */
enum {
	REGMAP_ROW_intro,
#define X(name) REGMAP_ROW_##name,
	ORFA_DRIVER_LIST
#undef X
	REGMAP_ROW_sys
};

/* Each register's driver row, made by the compiler from the start
 * registers: selecting is one flash read (a walk over the starts, which
 * avr-gcc unrolled, was 60 bytes more). */
_Static_assert(REGMAP_INTRO_REG == 0, "introspection starts the map");
static const ORFA_FLASH uint8_t regmap_row_of[REGMAP_END] = {
	[REGMAP_INTRO_REG ... REGMAP_LAST_intro] = REGMAP_ROW_intro,
#define X(name) [REGMAP_START_##name ... REGMAP_LAST_##name] = REGMAP_ROW_##name,
	ORFA_DRIVER_LIST
#undef X
	[REGMAP_START_sys ... REGMAP_LAST_sys] = REGMAP_ROW_sys,
};

/* Start registers on their own: a register's number within its driver. */
static const ORFA_FLASH uint8_t regmap_starts[] = {
	REGMAP_INTRO_REG,
#define X(name) REGMAP_START_##name,
	ORFA_DRIVER_LIST
#undef X
	REGMAP_START_sys,
};

/* Introspection records, made by the compiler. */
#define REGMAP_RECORD(uid, major, minor, start, nregs) \
	{ (uint8_t)((uid) >> 8), (uint8_t)(uid), major, minor, start, nregs }
static const ORFA_FLASH uint8_t regmap_records[][REGMAP_RECORD_LEN] = {
	REGMAP_RECORD(DRV_intro_UID, DRV_intro_MAJOR, DRV_intro_MINOR, REGMAP_INTRO_REG,
		      DRV_intro_NREGS),
#define X(name) REGMAP_RECORD(DRV_##name##_UID, DRV_##name##_MAJOR, DRV_##name##_MINOR, \
			      REGMAP_START_##name, DRV_##name##_NREGS),
	ORFA_DRIVER_LIST
#undef X
	REGMAP_RECORD(DRV_sys_UID, DRV_sys_MAJOR, DRV_sys_MINOR, REGMAP_START_sys, DRV_sys_NREGS),
};

_Static_assert(sizeof regmap_records <= 0x100, "a record's offset fits a byte");

/* selected.entry when no register is selected (after an unmapped one). */
#define REGMAP_NO_ENTRY 0xFF

/* The register that reads and writes go to, and how the last one ended. */
static struct {
	uint8_t reg;     /* selected register */
	uint8_t entry;   /* its driver's row's offset in regmap_table, or REGMAP_NO_ENTRY */
	uint8_t off;     /* the register's number within its driver */
	uint8_t status;  /* result of the last write or read that reached a driver */
} selected;

void regmap_init(void)
{
	for (uint8_t i = 0; i < REGMAP_NDRIVERS; i++) {
		regmap_table[i].init();
	}
	selected.reg = REGMAP_INTRO_REG;
	selected.entry = 0;
	selected.off = 0;
	selected.status = REG_OK;
}

/* The selected driver's row: its offset in the table kept as a byte at
 * selection (an index times 8 as a 16-bit product was a shift loop on
 * every call, on the latency path of every local request). */
_Static_assert((REGMAP_NDRIVERS - 1) * sizeof(regmap_entry_t) < REGMAP_NO_ENTRY,
	       "a row's offset in the table fits a byte, never REGMAP_NO_ENTRY");
static const ORFA_FLASH regmap_entry_t *regmap_row(void)
{
	return (const ORFA_FLASH regmap_entry_t *)((const ORFA_FLASH uint8_t *)regmap_table +
						   selected.entry);
}

bool regmap_select(uint8_t reg)
{
	if (reg >= REGMAP_END) {
		/* Nothing is selected now: a read gives nothing rather than
		 * the register selected before, and the status says 08. */
		selected.entry = REGMAP_NO_ENTRY;
		selected.status = REG_NO_REGISTER;
		return false;
	}
	uint8_t i = regmap_row_of[reg];
	selected.reg = reg;
	selected.entry = (uint8_t)(i * sizeof(regmap_entry_t));
	selected.off = (uint8_t)(reg - regmap_starts[i]);
	return true;
}

reg_status_t regmap_check_from(const uint8_t *data, uint8_t from, uint8_t len)
{
	if (from >= len) {
		return REG_OK;  /* nothing new (a frame of its register byte alone) */
	}
	if (selected.entry == REGMAP_NO_ENTRY) {
		return REG_NO_REGISTER;
	}
	if (selected.reg == REGMAP_STATUS_REG) {
		return REG_NOT_WRITABLE;
	}
	reg_status_t (*check)(uint8_t, const uint8_t *, uint8_t) = regmap_row()->check;
	uint8_t off = selected.off;
	reg_status_t st;

	do {
		st = check(off, data, ++from);
	} while (from < len && st == REG_OK);
	return st;
}

reg_status_t regmap_write(const uint8_t *data, uint8_t len)
{
	reg_status_t st;

	if (selected.entry == REGMAP_NO_ENTRY) {
		st = REG_NO_REGISTER;
	} else if (selected.reg == REGMAP_STATUS_REG) {
		st = REG_NOT_WRITABLE;
	} else {
		st = regmap_row()->write(selected.off, data, len);
	}
	selected.status = st;
	return st;
}

void regmap_read_start(void)
{
	if (selected.reg != REGMAP_STATUS_REG && selected.entry != REGMAP_NO_ENTRY) {
		selected.status = REG_OK;
	}
}

uint8_t regmap_read(uint8_t *dst, uint8_t max)
{
	if (selected.entry == REGMAP_NO_ENTRY) {
		return 0;  /* nothing selected: nothing to read, the status keeps 08 */
	}
	if (selected.reg == REGMAP_STATUS_REG) {
		/* Reading the status leaves it as it is. */
		for (uint8_t i = 0; i < max; i++) {
			dst[i] = selected.status;
		}
		return max;
	}
	uint8_t got = regmap_row()->read(selected.off, dst, max);
	if (got == 0) {  /* (a driver gives at most max: tests/unit checks each) */
		selected.status = REG_NOT_READABLE;
		return 0;
	}
	return got;
}

void regmap_safe(void)
{
	/* Each driver's DRV_<name>_SAFE(): a call, or nothing. */
#define X(name) DRV_##name##_SAFE();
	ORFA_DRIVER_LIST
#undef X
}

void regmap_later(void)
{
	/* Each driver's DRV_<name>_LATER(): a call, or nothing. */
#define X(name) DRV_##name##_LATER();
	ORFA_DRIVER_LIST
#undef X
}

reg_status_t regmap_status(void)
{
	return (reg_status_t)selected.status;
}

void regmap_set_status(reg_status_t status)
{
	selected.status = status;
}

uint8_t regmap_driver_count(void)
{
	return REGMAP_NDRIVERS;
}

void regmap_driver_record(uint8_t n, uint8_t *dst, uint8_t len)
{
	/* the record's offset as a byte: an 8-bit product, not a 16-bit one */
	const ORFA_FLASH uint8_t *r = &regmap_records[0][0] +
				      (uint8_t)((uint8_t)(n - 1) * REGMAP_RECORD_LEN);
	/* counted down, pointers walking: the tightest loop avr-gcc makes here
	 * (on the latency path of every introspection read) */
	while (len--) {
		*dst++ = *r++;
	}
}
