/*
 * bmp280.c: a Bosch BMP280 barometer on the simulated I2C bus, at register
 * level after Bosch's datasheet (BST-BMP280-DS001):
 *  - 8-bit addresses EC (SDO low) and EE (SDO high);
 *  - writes are pairs of register address and value (no auto-increment on
 *    writes); a read goes on from the last register address written,
 *    auto-incrementing; the address is kept across STOP;
 *  - id 0xD0 reads 0x58; reset 0xE0 written with 0xB6 resets everything
 *    (reads 0x00); status 0xF3: measuring (bit 3) while a conversion runs,
 *    im_update (bit 0) while the NVM is copied (2 ms, the start-up time,
 *    after power-up and a reset); ctrl_meas 0xF4: osrs_t, osrs_p, mode
 *    (00 sleep, 01/10 forced, 11 normal); config 0xF5: t_sb, filter,
 *    spi3w_en; calibration words dig_T1..dig_P9 at 0x88..0x9F, LSB first;
 *    raw pressure 0xF7..0xF9 and temperature 0xFA..0xFC, 20 bits, MSB
 *    first, the low nibble in bits 7:4 of xlsb; reset values 80 00 00;
 *  - oversampling 000 skips the measurement (its registers read 0x80000),
 *    001..101 are x1..x16 (110, 111 x16 too); with the filter off the
 *    result has 16 + (osrs - 1) bits (the lower ones 0), with it 20 bits;
 *  - the measurement time (datasheet section 9, typical): 1 ms + 2 ms per
 *    temperature sample + (2 ms per pressure sample + 0.5 ms); forced mode
 *    measures once and goes back to sleep (ctrl_meas reads mode 00 after);
 *    normal mode measures every measurement time + t_sb (0.5, 62.5, 125,
 *    250, 500, 1000, 2000, 4000 ms);
 *  - the data registers are shadowed: a read transfer sees the results
 *    there were at its address;
 *  - writes to config in normal mode are ignored (the datasheet: "may be";
 *    drivers put the part to sleep first).
 * What is sensed (control request `sense @EC temp T` / `pressure P`) comes
 * back through the datasheet's compensation formulas: each measurement
 * finds, by bisection on the datasheet's own formula (the double version),
 * the raw value of its resolution whose compensated value is nearest.
 * Not modelled: the IIR filter's response to a change (only its resolution:
 * a filtered constant is the constant), noise, SPI.
 */
#include <stdio.h>
#include <string.h>

#include "parts/part.h"
#include "parts/regdev.h"

#define BMP280_CHIP_ID 0x58
#define BMP280_RESET_WORD 0xB6
#define BMP280_SKIPPED 0x80000
#define BMP280_STARTUP_US 2000

enum {
	BMP280_REG_CALIB = 0x88,	/* .. 0x9F: dig_T1 .. dig_P9 */
	BMP280_REG_ID = 0xD0,
	BMP280_REG_RESET = 0xE0,
	BMP280_REG_STATUS = 0xF3,
	BMP280_REG_CTRL_MEAS = 0xF4,
	BMP280_REG_CONFIG = 0xF5,
	BMP280_REG_PRESS = 0xF7,	/* msb, lsb, xlsb */
	BMP280_REG_TEMP = 0xFA,		/* msb, lsb, xlsb */
};

#define BMP280_STATUS_MEASURING 0x08
#define BMP280_STATUS_IM_UPDATE 0x01
#define BMP280_MODE_NORMAL 3

/* The datasheet's example calibration (section 3.12): adc_T 519888 is
 * 25.08 degrees C, adc_P 415148 then 100653.27 Pa. */
static const uint16_t bmp280_dig_t1 = 27504;
static const int16_t bmp280_dig_t[3] = { 0, 26435, -1000 };		/* [1], [2] */
static const uint16_t bmp280_dig_p1 = 36477;
static const int16_t bmp280_dig_p[10] = { 0, 0, -10685, 3024, 2855, 140, -7, 15500,
					    -14600, 6000 };		/* [2] .. [9] */

typedef struct bmp280_t {
	regdev_t rd;			/* first: the I2C side, register/value writes */
	uint8_t ctrl_meas, config;
	uint8_t data[6];		/* 0xF7..0xFC as read */
	uint64_t copy_until;		/* im_update until this cycle */
	uint64_t meas_start;		/* the measurement (normal: the first) began */
	uint64_t meas_cycles;		/* one measurement lasts */
	uint64_t period;		/* normal mode: measurement + standby */
	uint64_t latched;		/* normal mode: measurements in data[] */
	int measuring;			/* forced: one under way; normal: running */
	double temp_c, press_pa;	/* what it senses */
} bmp280_t;

/* --- the datasheet's compensation (section 3.11.3, 8.1, 8.2) ------------- */

/* Degrees C of ADC_T (the double version); *T_FINE as it sets it. */
static double bmp280_temp_double(int32_t adc_t, int32_t *t_fine)
{
	double var1, var2;

	var1 = (adc_t / 16384.0 - bmp280_dig_t1 / 1024.0) * bmp280_dig_t[1];
	var2 = (adc_t / 131072.0 - bmp280_dig_t1 / 8192.0) *
	       (adc_t / 131072.0 - bmp280_dig_t1 / 8192.0) * bmp280_dig_t[2];
	*t_fine = (int32_t)(var1 + var2);
	return (var1 + var2) / 5120.0;
}

/* Pa of ADC_P at T_FINE (the double version). */
static double bmp280_press_double(int32_t adc_p, int32_t t_fine)
{
	const int16_t *d = bmp280_dig_p;
	double var1, var2, p;

	var1 = t_fine / 2.0 - 64000.0;
	var2 = var1 * var1 * d[6] / 32768.0;
	var2 = var2 + var1 * d[5] * 2.0;
	var2 = var2 / 4.0 + d[4] * 65536.0;
	var1 = (d[3] * var1 * var1 / 524288.0 + d[2] * var1) / 524288.0;
	var1 = (1.0 + var1 / 32768.0) * bmp280_dig_p1;
	if (var1 == 0.0) {
		return 0;
	}
	p = 1048576.0 - adc_p;
	p = (p - var2 / 4096.0) * 6250.0 / var1;
	var1 = d[9] * p * p / 2147483648.0;
	var2 = p * d[8] / 32768.0;
	return p + (var1 + var2 + d[7]) / 16.0;
}

/* The compensated value of a raw one: rising or falling with it. */
typedef double (*bmp280_formula_t)(int32_t adc, int32_t t_fine);

static double bmp280_temp_of(int32_t adc, int32_t unused)
{
	int32_t t_fine;

	(void)unused;
	return bmp280_temp_double(adc, &t_fine);
}

/* The raw value on the grid of STEP (a power of two: the resolution) in
 * 0..2^20 - STEP whose F (at T_FINE) is nearest WANT: bisection, since
 * F is monotonic over the grid (rising: temperature; falling: pressure). */
static int32_t bmp280_invert(bmp280_formula_t f, int32_t t_fine, double want, int32_t step)
{
	int32_t lo = 0, hi = (1 << 20) / step - 1;
	int rising = f(hi * step, t_fine) > f(0, t_fine);

	while (lo < hi) {
		int32_t mid = lo + (hi - lo) / 2;
		double v = f(mid * step, t_fine);

		if (rising ? v < want : v > want) {
			lo = mid + 1;	/* the first grid point at or beyond WANT is above */
		} else {
			hi = mid;
		}
	}
	/* lo: the first at or beyond WANT (or the last); its lower neighbour
	 * may be nearer */
	if (lo > 0) {
		double a = f((lo - 1) * step, t_fine) - want, b = f(lo * step, t_fine) - want;

		if ((a < 0 ? -a : a) <= (b < 0 ? -b : b)) {
			lo--;
		}
	}
	return lo * step;
}

/* --- measurements ---------------------------------------------------------- */

/* The oversampling of an osrs field: 0 (skipped), 1, 2, 4, 8, 16. */
static int bmp280_samples(unsigned osrs)
{
	return osrs == 0 ? 0 : osrs >= 5 ? 16 : 1 << (osrs - 1);
}

/* The grid of a result: 1 << (20 - bits), bits 16 + (osrs - 1) with the
 * filter off, 20 with it on. */
static int32_t bmp280_step(const bmp280_t *b, unsigned osrs)
{
	int bits = (b->config >> 2) & 7 ? 20 : 15 + (osrs >= 5 ? 5 : (int)osrs);

	return 1 << (20 - bits);
}

static uint64_t bmp280_us(const bmp280_t *b, uint64_t us)
{
	return (uint64_t)b->rd.hz * us / 1000000u;
}

/* The typical measurement time of ctrl_meas, in cycles. */
static uint64_t bmp280_meas_cycles(const bmp280_t *b)
{
	int t = bmp280_samples(b->ctrl_meas >> 5), p = bmp280_samples((b->ctrl_meas >> 2) & 7);

	return bmp280_us(b, 1000u + 2000u * (unsigned)t + (p ? 2000u * (unsigned)p + 500u : 0));
}

static void bmp280_put20(uint8_t *r, int32_t v)
{
	r[0] = (uint8_t)(v >> 12);
	r[1] = (uint8_t)(v >> 4);
	r[2] = (uint8_t)((v & 0xF) << 4);
}

/* A measurement ends: the raw values of what is sensed now, at the
 * resolution ctrl_meas and config set, into the data registers. */
static void bmp280_convert(bmp280_t *b)
{
	unsigned osrs_t = b->ctrl_meas >> 5, osrs_p = (b->ctrl_meas >> 2) & 7;
	int32_t adc_t, t_fine;

	adc_t = bmp280_invert(bmp280_temp_of, 0, b->temp_c, bmp280_step(b, osrs_t ? osrs_t : 5));
	bmp280_temp_double(adc_t, &t_fine);
	bmp280_put20(&b->data[3], osrs_t ? adc_t : BMP280_SKIPPED);
	bmp280_put20(&b->data[0], osrs_p ? bmp280_invert(bmp280_press_double, t_fine, b->press_pa,
							 bmp280_step(b, osrs_p))
				       : BMP280_SKIPPED);
}

/* Bring the data registers up to cycle NOW: measurements that ended. */
static void bmp280_update(bmp280_t *b, uint64_t now)
{
	uint64_t done;

	if (!b->measuring || now < b->meas_start + b->meas_cycles) {
		return;
	}
	if ((b->ctrl_meas & 3) != BMP280_MODE_NORMAL) {
		b->measuring = 0;
		b->ctrl_meas &= (uint8_t)~3;	/* forced: back to sleep */
		bmp280_convert(b);
		return;
	}
	done = (now - b->meas_start - b->meas_cycles) / b->period + 1;
	if (done != b->latched) {
		b->latched = done;
		bmp280_convert(b);
	}
}

static uint8_t bmp280_status(const bmp280_t *b, uint64_t now)
{
	uint8_t s = now < b->copy_until ? BMP280_STATUS_IM_UPDATE : 0;

	if (b->measuring && now >= b->meas_start) {
		uint64_t in = now - b->meas_start;

		if ((b->ctrl_meas & 3) == BMP280_MODE_NORMAL) {
			in %= b->period;
		}
		if (in < b->meas_cycles) {
			s |= BMP280_STATUS_MEASURING;
		}
	}
	return s;
}

/* t_sb of config in microseconds. */
static uint64_t bmp280_standby_us(const bmp280_t *b)
{
	unsigned t_sb = b->config >> 5;

	return t_sb == 0 ? 500u : 62500u << (t_sb - 1);
}

static void bmp280_reset(bmp280_t *b, uint64_t now)
{
	static const uint8_t data_reset[6] = { 0x80, 0, 0, 0x80, 0, 0 };

	b->ctrl_meas = b->config = 0;
	memcpy(b->data, data_reset, sizeof(b->data));
	b->measuring = 0;
	b->copy_until = now + bmp280_us(b, BMP280_STARTUP_US);
}

static void bmp280_write_reg(bmp280_t *b, uint8_t reg, uint8_t v, uint64_t now)
{
	switch (reg) {
	case BMP280_REG_RESET:
		if (v == BMP280_RESET_WORD) {
			bmp280_reset(b, now);
		}
		break;
	case BMP280_REG_CTRL_MEAS:
		bmp280_update(b, now);
		b->ctrl_meas = v;
		b->measuring = (v & 3) != 0;
		b->meas_start = now;
		b->meas_cycles = bmp280_meas_cycles(b);
		b->period = b->meas_cycles + bmp280_us(b, bmp280_standby_us(b));
		b->latched = 0;
		break;
	case BMP280_REG_CONFIG:
		if ((b->ctrl_meas & 3) != BMP280_MODE_NORMAL) {
			b->config = v;
		}
		break;
	default:
		break;		/* read-only: ignored */
	}
}

static uint8_t bmp280_read_reg(const bmp280_t *b, uint8_t reg, uint64_t now)
{
	if (reg >= BMP280_REG_CALIB && reg < BMP280_REG_CALIB + 24) {
		int i = (reg - BMP280_REG_CALIB) / 2;
		uint16_t w = i == 0 ? bmp280_dig_t1 : i < 3 ? (uint16_t)bmp280_dig_t[i] :
			     i == 3 ? bmp280_dig_p1 : (uint16_t)bmp280_dig_p[i - 2];

		return (uint8_t)(reg & 1 ? w >> 8 : w);
	}
	if (reg >= BMP280_REG_PRESS) {
		return b->data[reg - BMP280_REG_PRESS];	/* 0xF7 .. 0xFC; 0xFD.. 0 */
	}
	switch (reg) {
	case BMP280_REG_ID:
		return BMP280_CHIP_ID;
	case BMP280_REG_STATUS:
		return bmp280_status(b, now);
	case BMP280_REG_CTRL_MEAS:
		return b->ctrl_meas;
	case BMP280_REG_CONFIG:
		return b->config;
	default:
		return 0;	/* the reset register and what is not in the map */
	}
}

/* --- the bus (regdev) ---------------------------------------------------- */

static void bmp280_catch_up(regdev_t *d, uint64_t now)
{
	bmp280_update((bmp280_t *)d, now);	/* the shadow for this transfer */
}

static uint8_t bmp280_read(regdev_t *d, uint8_t reg)
{
	return bmp280_read_reg((bmp280_t *)d, reg, d->bus->cycle);
}

static void bmp280_write(regdev_t *d, uint8_t reg, uint8_t v)
{
	bmp280_write_reg((bmp280_t *)d, reg, v, d->bus->cycle);
}

static const regdev_ops_t bmp280_ops = {
	.catch_up = bmp280_catch_up,
	.read = bmp280_read,
	.write = bmp280_write,
	.ptr_mask = 0xff,
	.pairs = 1,
};

/* --- descriptor ------------------------------------------------------------ */

static void bmp280_part_init(void *self, const part_env_t *env)
{
	bmp280_t *b = self;

	regdev_init(&b->rd, env, &bmp280_ops);
	b->temp_c = 25.0;	/* a room at sea level until told otherwise */
	b->press_pa = 101325.0;
	bmp280_reset(b, 0);
}

/* The datasheet's operating range: -40..85 degrees C, 300..1100 hPa. */
static int bmp280_sense(void *self, uint64_t now, const char *quantity, const double *v, int n,
			char *err, size_t cap)
{
	bmp280_t *b = self;

	if (n == 1 && !strcmp(quantity, "temp")) {
		if (v[0] < -40 || v[0] > 85) {
			snprintf(err, cap, "temp T: -40..85 degrees C (the BMP280's range)");
			return -1;
		}
		bmp280_update(b, now);	/* measurements that ended saw the old value */
		b->temp_c = v[0];
		return 0;
	}
	if (n == 1 && !strcmp(quantity, "pressure")) {
		if (v[0] < 30000 || v[0] > 110000) {
			snprintf(err, cap, "pressure P: 30000..110000 Pa (the BMP280's range)");
			return -1;
		}
		bmp280_update(b, now);
		b->press_pa = v[0];
		return 0;
	}
	snprintf(err, cap, "a BMP280 senses temp T and pressure P, not %s with %d value%s",
		 quantity, n, n == 1 ? "" : "s");
	return -1;
}

const part_kind_t bmp280_kind = {
	.name = "bmp280",
	.attach = PART_I2C,
	.options = "",
	.about = "a Bosch BMP280 barometer (datasheet calibration)",
	.addrs = { { 0xEC, 0xEC }, { 0xEE, 0xEE } },
	.size = sizeof(bmp280_t),
	.init = bmp280_part_init,
	.sense = bmp280_sense,
	.senses = "temp, pressure",
};
