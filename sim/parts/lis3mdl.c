/*
 * lis3mdl.c: an ST LIS3MDL three-axis magnetometer on the simulated I2C bus,
 * after ST's datasheet DocID024204 (LIS3MDL, rev 5); docs/simulator.md lists
 * what is modelled and what is not.
 *
 * From the datasheet:
 *  - 8-bit addresses 38 (SDO/SA1 low; 7-bit 1C) and 3C (high; 7-bit 1E);
 *    WHO_AM_I (0F) reads 0x3D;
 *  - CTRL_REG1 (20, reset 0x10): TEMP_EN (7), OM (6:5) X/Y operating mode,
 *    DO (4:2) output rate 0.625, 1.25, 2.5, 5, 10 (reset), 20, 40, 80 Hz,
 *    FAST_ODR (1): 1000/560/300/155 Hz by OM (low-power .. ultra-high),
 *    ST (0); CTRL_REG2 (21, 0x00): FS (6:5) +-4/8/12/16 gauss at 6842/3421/
 *    2281/1711 LSB/gauss, REBOOT (3), SOFT_RST (2); CTRL_REG3 (22, 0x03):
 *    LP (5, forces 0.625 Hz), SIM (2), MD (1:0) 00 continuous, 01 single,
 *    10/11 power-down (reset); CTRL_REG4 (23, 0x00): OMZ (3:2), BLE (1);
 *    CTRL_REG5 (24, 0x00): FAST_READ (7), BDU (6); undefined bits read 0;
 *  - STATUS_REG (27): ZYXOR ZOR YOR XOR ZYXDA ZDA YDA XDA: a new sample
 *    sets an axis's DA; one that comes while DA is still set also sets OR;
 *  - OUT_X_L (28) .. OUT_Z_H (2D): two's complement, low byte at the lower
 *    address (BLE swaps); TEMP_OUT (2E, 2F) with TEMP_EN: 8 LSB per degree
 *    C, 0 at 25 degrees C;
 *  - BDU: the output registers are not updated until both bytes of the
 *    axis being read have been read;
 *  - INT_CFG (30, 0xE8), INT_SRC (31), INT_THS (32, 33) are kept;
 *  - the first byte written is the register address (SUB).
 *
 * Where the silicon differs from the datasheet, modelled as the silicon:
 *  - the datasheet says a multi-byte transfer auto-increments only with
 *    SUB bit 7 set; on I2C the chip increments without it, and maintained
 *    drivers rely on that: Adafruit's adafruit_lis3mdl reads X, Y, Z with
 *    one 6-byte read from 0x28, as do PX4's and Zephyr's drivers. Here
 *    SUB bit 7 is accepted and ignored: the address always moves on;
 *  - a read moving on from OUT_Z_H (2D) goes back to OUT_X_L (28), not to
 *    TEMP_OUT_L (PX4 issue 12514, a logic-analyser trace; PX4 reads the
 *    temperature with a read of its own for that reason).
 *
 * Assumptions (docs/simulator.md): the output registers change only
 * between transfers (a burst read sees one sample); in continuous mode the
 * first sample comes one period after MD is written, then one per period;
 * a single conversion takes one period at the set rate, then MD reads 11;
 * reading an axis's high byte clears its DA and OR, ZYXDA/ZYXOR are the OR
 * of the axes' bits; a reading beyond the full scale saturates at the full
 * scale (+-FS x sensitivity); SOFT_RST puts the control registers back to
 * their reset values and clears the outputs and status; REBOOT, self-test,
 * FAST_READ, the interrupt generator and the offset registers are not
 * modelled; registers outside the map read 0 and ignore writes.
 */
#include <stdio.h>
#include <string.h>

#include "parts/part.h"
#include "parts/regdev.h"

enum {
	LIS3MDL_WHO_AM_I = 0x0F,
	LIS3MDL_CTRL_REG1 = 0x20,
	LIS3MDL_CTRL_REG2 = 0x21,
	LIS3MDL_CTRL_REG3 = 0x22,
	LIS3MDL_CTRL_REG4 = 0x23,
	LIS3MDL_CTRL_REG5 = 0x24,
	LIS3MDL_STATUS_REG = 0x27,
	LIS3MDL_OUT_X_L = 0x28,
	LIS3MDL_OUT_Z_H = 0x2D,
	LIS3MDL_TEMP_OUT_L = 0x2E,
	LIS3MDL_TEMP_OUT_H = 0x2F,
	LIS3MDL_INT_CFG = 0x30,
	LIS3MDL_INT_THS_H = 0x33,
	LIS3MDL_NREGS = 0x34,
};

#define LIS3MDL_ID 0x3D
#define LIS3MDL_TEMP_EN 0x80
#define LIS3MDL_FAST_ODR 0x02
#define LIS3MDL_SOFT_RST 0x04
#define LIS3MDL_REBOOT 0x08
#define LIS3MDL_LP 0x20
#define LIS3MDL_MD_SINGLE 0x01
#define LIS3MDL_MD_OFF 0x03
#define LIS3MDL_BLE 0x02
#define LIS3MDL_BDU 0x40

/* Reset values and the bits a master may write, by register. */
static const uint8_t lis3mdl_reset[LIS3MDL_NREGS] = {
	[LIS3MDL_CTRL_REG1] = 0x10, [LIS3MDL_CTRL_REG3] = 0x03, [LIS3MDL_INT_CFG] = 0xE8,
};
static const uint8_t lis3mdl_writable[LIS3MDL_NREGS] = {
	[LIS3MDL_CTRL_REG1] = 0xFF, [LIS3MDL_CTRL_REG2] = 0x6C, [LIS3MDL_CTRL_REG3] = 0x27,
	[LIS3MDL_CTRL_REG4] = 0x0E, [LIS3MDL_CTRL_REG5] = 0xC0, [LIS3MDL_INT_CFG] = 0xEF,
	[0x32] = 0xFF, [LIS3MDL_INT_THS_H] = 0x7F,
};

static const double lis3mdl_lsb[4] = { 6842, 3421, 2281, 1711 };
static const uint32_t lis3mdl_odr_mhz[8] = { 625, 1250, 2500, 5000, 10000, 20000, 40000, 80000 };
static const uint32_t lis3mdl_fast_mhz[4] = { 1000000, 560000, 300000, 155000 };

typedef struct lis3mdl_t {
	regdev_t rd;			/* first: the bus's view, the pointer */
	uint8_t reg[LIS3MDL_NREGS];	/* control registers as written */
	int16_t out[3], temp_out;
	uint8_t status;
	uint8_t bytes_read;		/* output bytes read, bit per byte, an axis's
					 * two cleared once both are (BDU) */
	uint8_t pending;		/* a sample held back by BDU */
	part_ticker_t meas;
	double field[3];		/* sensed, microtesla */
	double temp;			/* sensed, degrees C */
} lis3mdl_t;

static void lis3mdl_sample(lis3mdl_t *l)
{
	int fs = (l->reg[LIS3MDL_CTRL_REG2] >> 5) & 3;
	double lsb = lis3mdl_lsb[fs];
	int32_t full = part_raw(4.0 * (fs + 1), lsb, INT16_MIN, INT16_MAX);

	if ((l->reg[LIS3MDL_CTRL_REG5] & LIS3MDL_BDU) && l->bytes_read) {
		l->pending = 1;
		return;
	}
	l->pending = 0;
	for (int i = 0; i < 3; i++) {
		l->out[i] = (int16_t)part_raw(l->field[i] / 100.0, lsb, -full, full);
		if (l->status & (1u << i)) {
			l->status |= (uint8_t)(0x10u << i);	/* overrun */
		}
		l->status |= (uint8_t)(1u << i);
	}
	if (l->reg[LIS3MDL_CTRL_REG1] & LIS3MDL_TEMP_EN) {
		l->temp_out = (int16_t)part_raw(l->temp - 25.0, 8.0, INT16_MIN, INT16_MAX);
	}
}

static void lis3mdl_catch_up(regdev_t *d, uint64_t now)
{
	lis3mdl_t *l = (lis3mdl_t *)d;
	uint64_t n = part_ticker_take(&l->meas, l->rd.hz, now);

	/* two samples or more: the last overwrote one nobody read (overrun) */
	for (uint64_t i = n < 2 ? n : 2; i; i--) {
		lis3mdl_sample(l);
	}
	if ((l->reg[LIS3MDL_CTRL_REG3] & 3) == LIS3MDL_MD_SINGLE && l->meas.limit &&
	    l->meas.taken >= l->meas.limit) {
		l->reg[LIS3MDL_CTRL_REG3] |= LIS3MDL_MD_OFF;
	}
}

/* Samples as CTRL_REG1 and CTRL_REG3 now ask, from NOW. */
static void lis3mdl_schedule(lis3mdl_t *l, uint64_t now)
{
	uint8_t r1 = l->reg[LIS3MDL_CTRL_REG1], r3 = l->reg[LIS3MDL_CTRL_REG3];
	uint64_t mhz = lis3mdl_odr_mhz[(r1 >> 2) & 7];

	if (r3 & LIS3MDL_LP) {
		mhz = lis3mdl_odr_mhz[0];
	} else if (r1 & LIS3MDL_FAST_ODR) {
		mhz = lis3mdl_fast_mhz[(r1 >> 5) & 3];
	}
	if ((r3 & 3) > LIS3MDL_MD_SINGLE) {
		part_ticker_stop(&l->meas);
		return;
	}
	part_ticker_start(&l->meas, now + ((uint64_t)l->rd.hz * 1000u + mhz - 1) / mhz, mhz,
			  (r3 & 3) == LIS3MDL_MD_SINGLE ? 1 : 0);
}

static void lis3mdl_reset_regs(lis3mdl_t *l)
{
	memcpy(l->reg, lis3mdl_reset, sizeof(l->reg));
	memset(l->out, 0, sizeof(l->out));
	l->temp_out = 0;
	l->status = 0;
	l->bytes_read = 0;
	l->pending = 0;
	part_ticker_stop(&l->meas);
}

/* Output byte at register R (28..2F): low byte at the even address unless BLE. */
static uint8_t lis3mdl_out_byte(lis3mdl_t *l, uint8_t r)
{
	int i = (r - LIS3MDL_OUT_X_L) / 2;
	uint16_t w = (uint16_t)(i < 3 ? l->out[i] : l->temp_out);
	int high = ((r - LIS3MDL_OUT_X_L) & 1) ^ !!(l->reg[LIS3MDL_CTRL_REG4] & LIS3MDL_BLE);

	if (i < 3) {
		l->bytes_read |= (uint8_t)(1u << (r - LIS3MDL_OUT_X_L));
		if (((l->bytes_read >> (2 * i)) & 3) == 3) {
			l->bytes_read &= (uint8_t)~(3u << (2 * i));
		}
		if (r & 1) {	/* OUT_x_H: its data are taken */
			l->status &= (uint8_t)~(0x11u << i);
		}
		if (l->pending && !l->bytes_read) {
			lis3mdl_sample(l);
		}
	}
	return high ? (uint8_t)(w >> 8) : (uint8_t)w;
}

static uint8_t lis3mdl_reg_read(regdev_t *d, uint8_t r)
{
	lis3mdl_t *l = (lis3mdl_t *)d;
	if (r == LIS3MDL_WHO_AM_I) {
		return LIS3MDL_ID;
	}
	if (r == LIS3MDL_STATUS_REG) {
		uint8_t s = l->status;

		return (uint8_t)(s | ((s & 0x07) ? 0x08 : 0) | ((s & 0x70) ? 0x80 : 0));
	}
	if (r >= LIS3MDL_OUT_X_L && r <= LIS3MDL_TEMP_OUT_H) {
		return lis3mdl_out_byte(l, r);
	}
	return r < LIS3MDL_NREGS ? l->reg[r] : 0;
}

static void lis3mdl_reg_write(regdev_t *d, uint8_t r, uint8_t v)
{
	lis3mdl_t *l = (lis3mdl_t *)d;
	uint64_t now = l->rd.bus->cycle;

	if (r >= LIS3MDL_NREGS || !lis3mdl_writable[r]) {
		return;
	}
	lis3mdl_catch_up(&l->rd, now);
	if (r == LIS3MDL_CTRL_REG2 && (v & LIS3MDL_SOFT_RST)) {
		lis3mdl_reset_regs(l);
		return;
	}
	if (r == LIS3MDL_CTRL_REG2) {
		v &= (uint8_t)~LIS3MDL_REBOOT;	/* done at once */
	}
	l->reg[r] = (uint8_t)((v & lis3mdl_writable[r]) | (r == LIS3MDL_INT_CFG ? 0x08 : 0));
	if (r == LIS3MDL_CTRL_REG1 || r == LIS3MDL_CTRL_REG3) {
		lis3mdl_schedule(l, now);
	}
}

/* The address after an access to R: on, except from OUT_Z_H back to OUT_X_L. */
static uint8_t lis3mdl_next(uint8_t r)
{
	return r == LIS3MDL_OUT_Z_H ? LIS3MDL_OUT_X_L : (uint8_t)((r + 1) & 0x7F);
}

static const regdev_ops_t lis3mdl_rd_ops = {
	.catch_up = lis3mdl_catch_up,
	.read = lis3mdl_reg_read,
	.write = lis3mdl_reg_write,
	.next = lis3mdl_next,
	.ptr_mask = 0x7F,		/* SUB bit 7 ignored: the silicon */
};

/* --- descriptor ------------------------------------------------------------ */

static void lis3mdl_part_init(void *self, const part_env_t *env)
{
	lis3mdl_t *l = self;

	regdev_init(&l->rd, env, &lis3mdl_rd_ops);
	l->temp = 25.0;
	lis3mdl_reset_regs(l);
}

/* Its widest range, +-16 gauss; the temperature sensor's. */
static const part_sense_t lis3mdl_senses[] = {
	{ "field", 3, -1600, 1600, "+-16 gauss, its widest range", offsetof(lis3mdl_t, field) },
	{ "temp", 1, -40, 85, "its operating range", offsetof(lis3mdl_t, temp) },
};

const part_kind_t lis3mdl_kind = {
	.name = "lis3mdl",
	.attach = PART_I2C,
	.options = "",
	.about = "an ST LIS3MDL three-axis magnetometer + thermometer",
	.addrs = { { 0x38, 0x38 }, { 0x3C, 0x3C } },
	.size = sizeof(lis3mdl_t),
	.init = lis3mdl_part_init,
	.sense_table = lis3mdl_senses,
	.nsense = 2,
	.who = "an LIS3MDL",
	.before_sense = regdev_catch_up,
};
