/*
 * hmc5883l.c: a Honeywell HMC5883L three-axis compass on the simulated I2C
 * bus, after Honeywell's "3-Axis Digital Compass IC HMC5883L" datasheet
 * (Form #900405 Rev E); docs/simulator.md lists what is modelled and what
 * is not.
 *
 * From the datasheet:
 *  - 8-bit address 3C (7-bit 1E), no other; registers 00 CRA (reset 0x10),
 *    01 CRB (0x20), 02 mode (0x01), 03..08 data X, Z, Y (in that order),
 *    each high byte first, 09 status, 10..12 identification 'H' '4' '3';
 *  - the first byte written is the register pointer; it moves on after
 *    every byte read or written, from 08 back to 03 (six bytes read from 03
 *    leave it at 03 for the next read: the datasheet's examples) and from
 *    12 and above to 00; it stays across STOP and repeated START; an
 *    invalid address reads 0, writes to it and to undefined bits are
 *    ignored (CRA bit 7, CRB bits 4:0, mode bits 6:2);
 *  - CRA: MA (bits 6:5) samples averaged; DO (bits 4:2) the continuous
 *    output rate 0.75, 1.5, 3, 7.5, 15 (reset), 30, 75 Hz (7 reserved: taken
 *    as 75); MS (bits 1:0) normal, positive bias, negative bias;
 *  - CRB GN (bits 7:5): 1370, 1090 (reset), 820, 660, 440, 390, 330, 230
 *    LSB/gauss; a data register holds -2048..2047; a reading beyond that
 *    (ADC overflow or underflow) holds -4096 until the next valid one;
 *    the first measurement after a gain change still uses the old gain;
 *  - mode MD (bits 1:0): 00 continuous, 01 single (reset), 10 and 11 idle;
 *    a single measurement puts its result in the data registers 6 ms after
 *    the write, then the mode register reads idle (0x03) (also at power-up:
 *    the datasheet's 'nominal 56 ms' to the first measurement); MR bit 7
 *    (HS) is kept;
 *  - status: RDY (bit 0) set when new data is in all six data registers,
 *    cleared for 250 us while new data is being written and once all six
 *    have been read; LOCK (bit 1) set when some but not all six data
 *    registers have been read, or the mode register has: new data is not
 *    placed until all six have been read, the mode register or CRA is
 *    written;
 *  - positive/negative bias (self test): the data registers hold the
 *    self-test field the bias current makes, +-1.16 gauss on X and Y,
 *    +-1.08 gauss on Z.
 *
 * Assumptions (docs/simulator.md): in continuous mode the first result
 * comes 6 ms after the write to the mode register or CRA (the datasheet's
 * measurement period; its example waits 6 ms), then one each 1/DO; a
 * result is the field sensed at its moment; in a bias mode the ambient
 * field cancels out; averaging changes nothing (no noise).
 */
#include <stdio.h>
#include <string.h>

#include "parts/part.h"
#include "parts/regdev.h"

enum {
	HMC5883L_CRA = 0,
	HMC5883L_CRB = 1,
	HMC5883L_MODE = 2,
	HMC5883L_DATA = 3,		/* X MSB .. Y LSB: 03..08 */
	HMC5883L_DATA_END = 8,
	HMC5883L_STATUS = 9,
	HMC5883L_ID = 10,		/* 'H' '4' '3': 10..12 */
	HMC5883L_ID_END = 12,
};

#define HMC5883L_RDY 0x01
#define HMC5883L_LOCK 0x02
#define HMC5883L_MD_SINGLE 0x01
#define HMC5883L_MD_IDLE 0x03
#define HMC5883L_OVERFLOW (-4096)
#define HMC5883L_MEASURE_US 6000u	/* from the command to the data */
#define HMC5883L_POWER_UP_US 56000u	/* to the power-up measurement */
#define HMC5883L_RDY_LOW_US 250u	/* RDY low while data are written */

static const uint8_t hmc5883l_writable[3] = { 0x7F, 0xE0, 0x83 };
static const double hmc5883l_gain[8] = { 1370, 1090, 820, 660, 440, 390, 330, 230 };
static const uint32_t hmc5883l_rate_mhz[8] = { 750, 1500, 3000, 7500, 15000, 30000, 75000, 75000 };
/* the self-test field of the bias current, gauss, X Y Z */
static const double hmc5883l_bias[3] = { 1.16, 1.16, 1.08 };

typedef struct hmc5883l_t {
	regdev_t rd;			/* first: the bus's view, the pointer */
	uint8_t reg[3];			/* CRA, CRB, mode */
	int16_t out[3];			/* data registers: X, Z, Y */
	int16_t pending[3];		/* a result held back by LOCK */
	uint8_t has_pending, rdy, lock;
	uint8_t read_mask;		/* data registers read (bit per register) */
	uint8_t gain;			/* GN the next measurement uses */
	part_ticker_t meas;		/* measurements to come */
	double field[3];		/* sensed, microtesla, X Y Z */
} hmc5883l_t;

static void hmc5883l_place(hmc5883l_t *h, const int16_t *v)
{
	memcpy(h->out, v, sizeof(h->out));
	h->rdy = 1;
	h->read_mask = 0;
	h->has_pending = 0;
}

/* One measurement, at the gain loaded by the one before. */
static void hmc5883l_measure(hmc5883l_t *h)
{
	static const int axis[3] = { 0, 2, 1 };	/* register order X, Z, Y */
	int ms = h->reg[HMC5883L_CRA] & 3;
	double gain = hmc5883l_gain[h->gain];
	int16_t v[3];

	for (int i = 0; i < 3; i++) {
		int a = axis[i];
		double gauss = ms == 1 ? hmc5883l_bias[a] : ms == 2 ? -hmc5883l_bias[a]
						 : h->field[a] / 100.0;
		int32_t raw = part_raw(gauss, gain, -4097, 4096);

		v[i] = raw < -2048 || raw > 2047 ? HMC5883L_OVERFLOW : (int16_t)raw;
	}
	h->gain = h->reg[HMC5883L_CRB] >> 5;
	if (h->lock) {
		memcpy(h->pending, v, sizeof(v));
		h->has_pending = 1;
	} else {
		hmc5883l_place(h, v);
	}
}

static void hmc5883l_catch_up(regdev_t *d, uint64_t now)
{
	hmc5883l_t *h = (hmc5883l_t *)d;
	uint64_t n = part_ticker_take(&h->meas, h->rd.hz, now);

	if (n > 2) {
		n = 2;		/* only the last two can differ (the gain rule) */
	}
	while (n--) {
		hmc5883l_measure(h);
	}
	if ((h->reg[HMC5883L_MODE] & 3) == HMC5883L_MD_SINGLE && h->meas.limit &&
	    h->meas.taken >= h->meas.limit) {
		h->reg[HMC5883L_MODE] = (uint8_t)((h->reg[HMC5883L_MODE] & 0x80) | HMC5883L_MD_IDLE);
	}
}

/* Measurements as the mode register and CRA now ask, from NOW. */
static void hmc5883l_schedule(hmc5883l_t *h, uint64_t now, uint32_t first_us)
{
	int md = h->reg[HMC5883L_MODE] & 3;
	uint64_t first = now + part_us(h->rd.hz, first_us);

	if (md == 0) {
		part_ticker_start(&h->meas, first, hmc5883l_rate_mhz[(h->reg[HMC5883L_CRA] >> 2) & 7],
				  0);
	} else if (md == HMC5883L_MD_SINGLE) {
		part_ticker_start(&h->meas, first, 1000, 1);
	} else {
		part_ticker_stop(&h->meas);
	}
}

static void hmc5883l_unlock(hmc5883l_t *h)
{
	h->lock = 0;
	h->read_mask = 0;
	if (h->has_pending) {
		hmc5883l_place(h, h->pending);
	}
}

static uint8_t hmc5883l_status(const hmc5883l_t *h)
{
	uint64_t next = part_ticker_next(&h->meas, h->rd.hz);
	uint64_t now = h->rd.bus->cycle;
	int writing = !h->lock && next != UINT64_MAX &&
		      now + part_us(h->rd.hz, HMC5883L_RDY_LOW_US) >= next;

	return (uint8_t)((h->rdy && !writing ? HMC5883L_RDY : 0) | (h->lock ? HMC5883L_LOCK : 0));
}

static uint8_t hmc5883l_reg_read(regdev_t *d, uint8_t r)
{
	hmc5883l_t *h = (hmc5883l_t *)d;
	static const char id[3] = { 'H', '4', '3' };

	if (r <= HMC5883L_MODE) {
		if (r == HMC5883L_MODE) {
			h->lock = 1;
		}
		return h->reg[r];
	}
	if (r <= HMC5883L_DATA_END) {
		int i = (r - HMC5883L_DATA) / 2;
		uint16_t w = (uint16_t)h->out[i];
		uint8_t v = (r - HMC5883L_DATA) & 1 ? (uint8_t)w : (uint8_t)(w >> 8);

		h->read_mask |= (uint8_t)(1u << (r - HMC5883L_DATA));
		if (h->read_mask == 0x3F) {
			h->rdy = 0;
			hmc5883l_unlock(h);
		} else {
			h->lock = 1;
		}
		return v;
	}
	if (r == HMC5883L_STATUS) {
		return hmc5883l_status(h);
	}
	if (r <= HMC5883L_ID_END) {
		return (uint8_t)id[r - HMC5883L_ID];
	}
	return 0;
}

static void hmc5883l_reg_write(regdev_t *d, uint8_t r, uint8_t v)
{
	hmc5883l_t *h = (hmc5883l_t *)d;
	uint64_t now = h->rd.bus->cycle;

	if (r > HMC5883L_MODE) {
		return;		/* read-only or invalid: ignored */
	}
	hmc5883l_catch_up(&h->rd, now);
	h->reg[r] = v & hmc5883l_writable[r];
	if (r == HMC5883L_CRA || r == HMC5883L_MODE) {
		hmc5883l_unlock(h);
		hmc5883l_schedule(h, now, HMC5883L_MEASURE_US);
	}
}

/* The pointer after an access to register R. */
static uint8_t hmc5883l_next(uint8_t r)
{
	if (r == HMC5883L_DATA_END) {
		return HMC5883L_DATA;
	}
	return r >= HMC5883L_ID_END ? 0 : (uint8_t)(r + 1);
}

static const regdev_ops_t hmc5883l_rd_ops = {
	.catch_up = hmc5883l_catch_up,
	.read = hmc5883l_reg_read,
	.write = hmc5883l_reg_write,
	.next = hmc5883l_next,
	.ptr_mask = 0xFF,
};

/* --- descriptor ------------------------------------------------------------ */

static void hmc5883l_part_init(void *self, const part_env_t *env)
{
	hmc5883l_t *h = self;

	regdev_init(&h->rd, env, &hmc5883l_rd_ops);
	h->reg[HMC5883L_CRA] = 0x10;
	h->reg[HMC5883L_CRB] = 0x20;
	h->reg[HMC5883L_MODE] = HMC5883L_MD_SINGLE;
	h->gain = 1;
	hmc5883l_schedule(h, env->bus->cycle, HMC5883L_POWER_UP_US);
}

/* Its field range: +-8 gauss. */
static const part_sense_t hmc5883l_senses[] = {
	{ "field", 3, -800, 800, "+-8 gauss", offsetof(hmc5883l_t, field) },
};

const part_kind_t hmc5883l_kind = {
	.name = "hmc5883l",
	.attach = PART_I2C,
	.options = "",
	.about = "a Honeywell HMC5883L three-axis compass",
	.addrs = { { 0x3C, 0x3C } },
	.size = sizeof(hmc5883l_t),
	.init = hmc5883l_part_init,
	.sense_table = hmc5883l_senses,
	.nsense = 1,
	.who = "an HMC5883L",
	.before_sense = regdev_catch_up,
};
