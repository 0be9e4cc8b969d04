#include "firmware/intro.h"

#define INTRO_RECORD_LEN 6

/* 0: the next read gives the driver count; n: it gives driver n. */
static uint8_t intro_cursor;

static void intro_init(void)
{
	intro_cursor = 0;
}

static reg_status_t intro_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)reg;
	if (len != 1) {
		return REG_BAD_LENGTH;
	}
	if (data[0] > regmap_driver_count()) {
		/* SPEC: an N above the count is an error and the next read gives
		 * driver 1. */
		intro_cursor = 1;
		return REG_BAD_VALUE;
	}
	intro_cursor = data[0];
	return REG_OK;
}

static uint8_t intro_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	(void)reg;
	if (intro_cursor == 0) {
		dst[0] = regmap_driver_count();
		intro_cursor = 1;
		return 1;
	}
	if (intro_cursor > regmap_driver_count()) {
		intro_cursor = 1;
		regmap_set_status(REG_READ_WRAPPED);
	}
	uint8_t rec[INTRO_RECORD_LEN];
	regmap_driver_record(intro_cursor, rec);
	intro_cursor++;
	uint8_t n = max < INTRO_RECORD_LEN ? max : INTRO_RECORD_LEN;
	for (uint8_t i = 0; i < n; i++) {
		dst[i] = rec[i];
	}
	return n;
}

const ORFA_FLASH drv_t drv_intro = {
	.uid = 0x0000,
	.major = 1,
	.minor = 0,
	.nregs = DRV_intro_NREGS,
	.init = intro_init,
	.write = intro_write,
	.read = intro_read,
};
