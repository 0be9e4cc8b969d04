/*
 * mpu6050.c: an InvenSense MPU-6050 gyroscope + accelerometer + temperature
 * sensor on the simulated I2C bus, after InvenSense's "MPU-6000 and
 * MPU-6050 Register Map and Descriptions" (RM-MPU-6000A-00 rev 4.2) and
 * "Product Specification" (PS-MPU-6000A-00 rev 3.4); docs/simulator.md
 * lists what is modelled and what is not.
 *
 * From the documents:
 *  - 8-bit addresses D0 (AD0 low) and D2 (AD0 high); WHO_AM_I (75) reads
 *    0x68 at either (the AD0 pin is not reflected in it);
 *  - the first byte written is the register address; every byte read or
 *    written after it moves the address on by one; the address stays
 *    across STOP and repeated START (a read without an address continues
 *    where the last transfer left off);
 *  - every register resets to 0 but PWR_MGMT_1 (6B) = 0x40, SLEEP set: the
 *    part powers up asleep and measures nothing until SLEEP is cleared;
 *    PWR_MGMT_1 bit 7 (DEVICE_RESET) puts every register back to its reset
 *    value and reads 0 again at once;
 *  - the sensor registers ACCEL_XOUT_H (3B) .. GYRO_ZOUT_L (48) are
 *    16-bit two's complement, high byte first, written at the sample rate
 *    (SMPLRT_DIV, 19: gyroscope output rate / (1 + SMPLRT_DIV), the
 *    gyroscope output rate 8 kHz with DLPF_CFG (CONFIG, 1A, bits 2:0) 0 or
 *    7, 1 kHz otherwise), and only while the serial interface is idle: a
 *    burst read sees one sampling instant;
 *  - ACCEL_CONFIG (1C) AFS_SEL (bits 4:3): +-2/4/8/16 g at 16384/8192/4096/
 *    2048 LSB/g; GYRO_CONFIG (1B) FS_SEL (bits 4:3): +-250/500/1000/2000
 *    degrees/s at 131/65.5/32.8/16.4 LSB per degree/s; a reading beyond the
 *    range saturates at -32768/32767;
 *  - TEMP_OUT (41, 42): degrees C = TEMP_OUT / 340 + 36.53; TEMP_DIS (6B
 *    bit 3) stops it; PWR_MGMT_2 (6C) STBY_XA..STBY_ZG (bits 5:0) stop an
 *    axis (its register keeps its last value);
 *  - CYCLE (6B bit 5, SLEEP clear): the accelerometer alone, sampled at
 *    LP_WAKE_CTRL (6C bits 7:6) 1.25/5/20/40 Hz;
 *  - INT_STATUS (3A) DATA_RDY_INT (bit 0) sets when the sensor registers
 *    are written, if INT_ENABLE (38) DATA_RDY_EN (bit 0) is set; reading
 *    INT_STATUS clears it (any read does, with INT_PIN_CFG (37) INT_RD_CLEAR,
 *    bit 4);
 *  - USER_CTRL (6A) SIG_COND_RESET (bit 0) clears the sensor registers;
 *    it, FIFO_RESET and I2C_MST_RESET read 0 again at once; SIGNAL_PATH_
 *    RESET (68) resets the signal paths, not the sensor registers;
 *  - the temperature sensor's range is -40..85 degrees C.
 *
 * Not modelled (assumptions in docs/simulator.md): the start-up time after
 * SLEEP is cleared (the first sample comes one sample period later), the
 * low-pass filter's delay (a sample is the value sensed at that moment),
 * self-test (the XA_ST.. bits are kept, the output does not move; SELF_TEST_X
 * .. _A read fixed values), the FIFO (FIFO_COUNT reads 0), the auxiliary
 * I2C master (its registers are kept, EXT_SENS_DATA reads 0), the
 * interrupt pin, noise and offsets.
 */
#include <stdio.h>
#include <string.h>

#include "parts/part.h"
#include "parts/regdev.h"

enum {
	MPU6050_SELF_TEST_X = 0x0D,
	MPU6050_SELF_TEST_A = 0x10,
	MPU6050_SMPLRT_DIV = 0x19,
	MPU6050_CONFIG = 0x1A,
	MPU6050_GYRO_CONFIG = 0x1B,
	MPU6050_ACCEL_CONFIG = 0x1C,
	MPU6050_INT_PIN_CFG = 0x37,
	MPU6050_INT_ENABLE = 0x38,
	MPU6050_INT_STATUS = 0x3A,
	MPU6050_ACCEL_XOUT_H = 0x3B,
	MPU6050_TEMP_OUT_H = 0x41,
	MPU6050_GYRO_XOUT_H = 0x43,
	MPU6050_GYRO_ZOUT_L = 0x48,
	MPU6050_SIGNAL_PATH_RESET = 0x68,
	MPU6050_USER_CTRL = 0x6A,
	MPU6050_PWR_MGMT_1 = 0x6B,
	MPU6050_PWR_MGMT_2 = 0x6C,
	MPU6050_WHO_AM_I = 0x75,
	MPU6050_NREGS = 0x76,
};

#define MPU6050_ID 0x68
#define MPU6050_PWR_MGMT_1_RESET 0x40
#define MPU6050_DEVICE_RESET 0x80
#define MPU6050_SLEEP 0x40
#define MPU6050_CYCLE 0x20
#define MPU6050_TEMP_DIS 0x08
#define MPU6050_DATA_RDY 0x01
#define MPU6050_INT_RD_CLEAR 0x10
#define MPU6050_SIG_COND_RESET 0x01
#define MPU6050_USER_CTRL_STROBES 0x07	/* FIFO_RESET, I2C_MST_RESET, SIG_COND_RESET */
#define MPU6050_G 9.80665		/* standard gravity, m/s^2 per g */

/* The registers a master may write (1) and read back as written: every one
 * of the register map's R/W registers; the rest are read-only or absent
 * (writes acknowledged and ignored). */
static const uint8_t mpu6050_rw[MPU6050_NREGS] = {
	[0x0D] = 1, [0x0E] = 1, [0x0F] = 1, [0x10] = 1,
	[0x19] = 1, [0x1A] = 1, [0x1B] = 1, [0x1C] = 1, [0x23] = 1,
	[0x24] = 1, [0x25] = 1, [0x26] = 1, [0x27] = 1, [0x28] = 1, [0x29] = 1, [0x2A] = 1,
	[0x2B] = 1, [0x2C] = 1, [0x2D] = 1, [0x2E] = 1, [0x2F] = 1, [0x30] = 1, [0x31] = 1,
	[0x32] = 1, [0x33] = 1, [0x34] = 1, [0x35] = 1,
	[0x37] = 1, [0x38] = 1,
	[0x63] = 1, [0x64] = 1, [0x65] = 1, [0x66] = 1, [0x67] = 1,
	[0x6A] = 1, [0x6B] = 1, [0x6C] = 1,
};

/* Factory self-test trim, SELF_TEST_X .. _A: each chip has its own; these
 * are plausible values, fixed so that tests can name them. */
static const uint8_t mpu6050_trim[4] = { 0x75, 0x77, 0x6B, 0x59 };

/* Gyroscope LSB per degree/s by FS_SEL. */
static const double mpu6050_gyro_lsb[4] = { 131.0, 65.5, 32.8, 16.4 };

/* LP_WAKE_CTRL's wake-up rates, millihertz. */
static const uint32_t mpu6050_wake_mhz[4] = { 1250, 5000, 20000, 40000 };

typedef struct mpu6050_t {
	regdev_t rd;			/* first: the bus's view, the pointer */
	uint8_t reg[MPU6050_NREGS];	/* the R/W registers as written */
	int16_t accel_out[3], temp_out, gyro_out[3];	/* the sensor registers */
	uint8_t int_status;
	part_ticker_t sampler;		/* the sample clock */
	/* what it senses */
	double accel[3], gyro[3], temp;
} mpu6050_t;

static void mpu6050_sample(mpu6050_t *m)
{
	uint8_t pm1 = m->reg[MPU6050_PWR_MGMT_1], pm2 = m->reg[MPU6050_PWR_MGMT_2];
	double accel_lsb = 16384.0 / (1 << ((m->reg[MPU6050_ACCEL_CONFIG] >> 3) & 3));
	double gyro_lsb = mpu6050_gyro_lsb[(m->reg[MPU6050_GYRO_CONFIG] >> 3) & 3];

	for (int i = 0; i < 3; i++) {
		if (!(pm2 & (0x20 >> i))) {
			m->accel_out[i] = (int16_t)part_raw(m->accel[i] / MPU6050_G, accel_lsb,
							    INT16_MIN, INT16_MAX);
		}
		if (!(pm2 & (0x04 >> i)) && !(pm1 & MPU6050_CYCLE)) {
			m->gyro_out[i] = (int16_t)part_raw(m->gyro[i], gyro_lsb, INT16_MIN,
							   INT16_MAX);
		}
	}
	if (!(pm1 & MPU6050_TEMP_DIS)) {
		m->temp_out = (int16_t)part_raw(m->temp - 36.53, 340.0, INT16_MIN, INT16_MAX);
	}
	if (m->reg[MPU6050_INT_ENABLE] & MPU6050_DATA_RDY) {
		m->int_status |= MPU6050_DATA_RDY;
	}
}

/* The samples due by cycle NOW: the last of them is in the registers. */
static void mpu6050_catch_up(regdev_t *d, uint64_t now)
{
	mpu6050_t *m = (mpu6050_t *)d;
	if (part_ticker_take(&m->sampler, m->rd.hz, now)) {
		mpu6050_sample(m);
	}
}

/* The sample clock as the power and rate registers now set it, from NOW:
 * the first sample one period on. */
static void mpu6050_clock(mpu6050_t *m, uint64_t now)
{
	uint8_t pm1 = m->reg[MPU6050_PWR_MGMT_1];
	uint64_t mhz;

	if (pm1 & MPU6050_SLEEP) {
		part_ticker_stop(&m->sampler);
		return;
	}
	if (pm1 & MPU6050_CYCLE) {
		mhz = mpu6050_wake_mhz[m->reg[MPU6050_PWR_MGMT_2] >> 6];
	} else {
		uint8_t dlpf = m->reg[MPU6050_CONFIG] & 7;

		mhz = (dlpf == 0 || dlpf == 7 ? 8000000u : 1000000u) /
		      (1u + m->reg[MPU6050_SMPLRT_DIV]);
	}
	part_ticker_start(&m->sampler, now + ((uint64_t)m->rd.hz * 1000u + mhz - 1) / mhz, mhz, 0);
}

static void mpu6050_reset(mpu6050_t *m)
{
	memset(m->reg, 0, sizeof(m->reg));
	memcpy(&m->reg[MPU6050_SELF_TEST_X], mpu6050_trim, sizeof(mpu6050_trim));
	m->reg[MPU6050_PWR_MGMT_1] = MPU6050_PWR_MGMT_1_RESET;
	memset(m->accel_out, 0, sizeof(m->accel_out));
	memset(m->gyro_out, 0, sizeof(m->gyro_out));
	m->temp_out = 0;
	m->int_status = 0;
	part_ticker_stop(&m->sampler);
}

static uint8_t mpu6050_reg_read(regdev_t *d, uint8_t r)
{
	mpu6050_t *m = (mpu6050_t *)d;
	uint8_t v;

	if (r >= MPU6050_ACCEL_XOUT_H && r <= MPU6050_GYRO_ZOUT_L) {
		int i = (r - MPU6050_ACCEL_XOUT_H) / 2;
		int16_t w = i < 3 ? m->accel_out[i] : i == 3 ? m->temp_out : m->gyro_out[i - 4];

		v = (r - MPU6050_ACCEL_XOUT_H) & 1 ? (uint8_t)w : (uint8_t)((uint16_t)w >> 8);
	} else if (r == MPU6050_INT_STATUS) {
		v = m->int_status;
		m->int_status = 0;
	} else if (r == MPU6050_WHO_AM_I) {
		v = MPU6050_ID;
	} else if (r < MPU6050_NREGS && mpu6050_rw[r]) {
		v = m->reg[r];
	} else {
		v = 0;		/* read-only registers of parts not modelled, absent ones */
	}
	if (m->reg[MPU6050_INT_PIN_CFG] & MPU6050_INT_RD_CLEAR) {
		m->int_status = 0;
	}
	return v;
}

static void mpu6050_reg_write(regdev_t *d, uint8_t r, uint8_t v)
{
	mpu6050_t *m = (mpu6050_t *)d;
	uint64_t now = m->rd.bus->cycle;

	if (r >= MPU6050_NREGS || !mpu6050_rw[r]) {
		return;
	}
	mpu6050_catch_up(&m->rd, now);
	if (r == MPU6050_PWR_MGMT_1 && (v & MPU6050_DEVICE_RESET)) {
		mpu6050_reset(m);
		return;
	}
	if (r == MPU6050_USER_CTRL) {
		if (v & MPU6050_SIG_COND_RESET) {
			memset(m->accel_out, 0, sizeof(m->accel_out));
			memset(m->gyro_out, 0, sizeof(m->gyro_out));
			m->temp_out = 0;
		}
		v &= (uint8_t)~MPU6050_USER_CTRL_STROBES;
	}
	m->reg[r] = v;
	if (r == MPU6050_PWR_MGMT_1 || r == MPU6050_PWR_MGMT_2 || r == MPU6050_SMPLRT_DIV ||
	    r == MPU6050_CONFIG) {
		mpu6050_clock(m, now);
	}
}

static const regdev_ops_t mpu6050_rd_ops = {
	.catch_up = mpu6050_catch_up,
	.read = mpu6050_reg_read,
	.write = mpu6050_reg_write,
	.next = NULL,
	.ptr_mask = 0xFF,
};

/* --- descriptor ------------------------------------------------------------ */

static void mpu6050_part_init(void *self, const part_env_t *env)
{
	mpu6050_t *m = self;

	regdev_init(&m->rd, env, &mpu6050_rd_ops);
	m->temp = 25.0;
	mpu6050_reset(m);
}

/* The widest ranges: +-16 g, +-2000 degrees/s; the temperature sensor's. */
static const part_sense_t mpu6050_senses[] = {
	{ "accel", 3, -16 * MPU6050_G, 16 * MPU6050_G, "+-16 g, its widest range",
	  offsetof(mpu6050_t, accel) },
	{ "gyro", 3, -2000, 2000, "its widest range", offsetof(mpu6050_t, gyro) },
	{ "temp", 1, -40, 85, "the temperature sensor's range", offsetof(mpu6050_t, temp) },
};

const part_kind_t mpu6050_kind = {
	.name = "mpu6050",
	.attach = PART_I2C,
	.options = "",
	.about = "an InvenSense MPU-6050 accelerometer + gyroscope + thermometer",
	.addrs = { { 0xD0, 0xD0 }, { 0xD2, 0xD2 } },
	.size = sizeof(mpu6050_t),
	.init = mpu6050_part_init,
	.sense_table = mpu6050_senses,
	.nsense = 3,
	.who = "an MPU-6050",
	.before_sense = regdev_catch_up,
};
