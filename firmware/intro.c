#include "firmware/intro.h"

/* 0: reads give the driver count (and stay there, as in ORFA 0.7.5, whose
 * hosts read the count again); n: the next read gives driver n. */
static uint8_t intro_cursor;

void drv_intro_init(void)
{
	intro_cursor = 0;
}

reg_status_t drv_intro_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)reg;
	if (len != 1) {
		return REG_BAD_LENGTH;
	}
	if (data[0] > regmap_driver_count()) {
		/* docs/registers.md: an N above the count is an error and the next read gives
		 * driver 1. */
		intro_cursor = 1;
		return REG_BAD_VALUE;
	}
	intro_cursor = data[0];
	return REG_OK;
}

reg_status_t drv_intro_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)reg;
	(void)data;
	/* An N above the count is left to the write: it also moves the
	 * cursor to driver 1. */
	return len > 1 ? REG_BAD_LENGTH : REG_OK;
}

uint8_t drv_intro_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	uint8_t cursor = intro_cursor;

	(void)reg;
	if (cursor == 0) {
		dst[0] = regmap_driver_count();
		return 1;
	}
	if (cursor > regmap_driver_count()) {
		cursor = 1;
		regmap_set_status(REG_READ_WRAPPED);
	}
	uint8_t n = max < REGMAP_RECORD_LEN ? max : REGMAP_RECORD_LEN;
	regmap_driver_record(cursor, dst, n);
	intro_cursor = (uint8_t)(cursor + 1);
	return n;
}
