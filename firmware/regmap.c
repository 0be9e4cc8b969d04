#include "firmware/regmap.h"

#include "drivers/drivers.h"

/* Start registers, computed by the compiler: each driver starts right after
 * the last register of the one before it. */
enum {
	REGMAP_LAST_intro = DRV_intro_NREGS - 1,
#define X(name) \
	REGMAP_START_##name, \
	REGMAP_LAST_##name = REGMAP_START_##name + DRV_##name##_NREGS - 1,
	ORFA_DRIVER_LIST
#undef X
	REGMAP_END
};

_Static_assert(REGMAP_END <= 0x100, "registers must fit in one byte");

typedef struct {
	const ORFA_FLASH drv_t *drv;
	uint8_t start;
} regmap_entry_t;

static const ORFA_FLASH regmap_entry_t regmap_table[] = {
	{ &drv_intro, REGMAP_INTRO_REG },
#define X(name) { &drv_##name, REGMAP_START_##name },
	ORFA_DRIVER_LIST
#undef X
};

#define REGMAP_NDRIVERS ((uint8_t)(sizeof regmap_table / sizeof regmap_table[0]))

static struct {
	uint8_t reg;     /* selected register */
	uint8_t entry;   /* its driver's index in regmap_table */
	uint8_t status;  /* result of the last write or read that reached a driver */
} rm;

void regmap_init(void)
{
	for (uint8_t i = 0; i < REGMAP_NDRIVERS; i++) {
		void (*init)(void) = regmap_table[i].drv->init;
		if (init) {
			init();
		}
	}
	rm.reg = REGMAP_INTRO_REG;
	rm.entry = 0;
	rm.status = REG_OK;
}

bool regmap_select(uint8_t reg)
{
	if (reg >= REGMAP_END) {
		return false;
	}
	uint8_t i = REGMAP_NDRIVERS - 1;
	while (regmap_table[i].start > reg) {
		i--;
	}
	rm.reg = reg;
	rm.entry = i;
	return true;
}

reg_status_t regmap_write(const uint8_t *data, uint8_t len)
{
	const ORFA_FLASH regmap_entry_t *e = &regmap_table[rm.entry];
	reg_status_t (*write)(uint8_t, const uint8_t *, uint8_t) = e->drv->write;
	reg_status_t st;

	if (rm.reg == REGMAP_STATUS_REG || !write) {
		st = REG_NOT_WRITABLE;
	} else {
		st = write((uint8_t)(rm.reg - e->start), data, len);
	}
	rm.status = st;
	return st;
}

reg_status_t regmap_read(uint8_t *dst, uint8_t n)
{
	if (rm.reg == REGMAP_STATUS_REG) {
		/* Reading the status leaves it as it is. */
		for (uint8_t i = 0; i < n; i++) {
			dst[i] = rm.status;
		}
		return REG_OK;
	}
	const ORFA_FLASH regmap_entry_t *e = &regmap_table[rm.entry];
	uint8_t (*read)(uint8_t, uint8_t *, uint8_t) = e->drv->read;
	uint8_t reg = (uint8_t)(rm.reg - e->start);

	rm.status = REG_OK;
	while (n) {
		uint8_t got = read ? read(reg, dst, n) : 0;
		if (got == 0 || got > n) {
			rm.status = REG_NOT_READABLE;
			return REG_NOT_READABLE;
		}
		dst += got;
		n = (uint8_t)(n - got);
	}
	return REG_OK;
}

void regmap_set_status(reg_status_t status)
{
	rm.status = status;
}

uint8_t regmap_driver_count(void)
{
	return REGMAP_NDRIVERS;
}

void regmap_driver_record(uint8_t n, uint8_t rec[6])
{
	const ORFA_FLASH regmap_entry_t *e = &regmap_table[n - 1];
	const ORFA_FLASH drv_t *d = e->drv;
	rec[0] = (uint8_t)(d->uid >> 8);
	rec[1] = (uint8_t)d->uid;
	rec[2] = d->major;
	rec[3] = d->minor;
	rec[4] = e->start;
	rec[5] = d->nregs;
}
