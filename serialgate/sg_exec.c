#include "serialgate/sg_exec.h"

#include <stdbool.h>

#include "firmware/flash.h"
#include "firmware/regmap.h"
#include "firmware/twi_master.h"
#include "firmware/xact.h"

static struct {
	uint8_t local;  /* local address, bit 0 clear */
	uint16_t khz;   /* bus clock actually set */
} gate;

static inline uint8_t hex_digit(uint8_t d)
{
	return (uint8_t)(d < 10 ? '0' + d : 'A' - 10 + d);
}

/* A byte's two digits in one call: a read's reply is mostly these. */
static void out_hex(uint8_t b)
{
	sg_out2(hex_digit(b >> 4), hex_digit(b & 0x0F));
}

static void out_end(void)
{
	sg_out2('\r', '\n');
}

static void out_error(uint8_t err)
{
	static const ORFA_FLASH char text[] = "ERROR ";
	for (uint8_t i = 0; i < sizeof text - 1; i++) {
		sg_out((uint8_t)text[i]);
	}
	out_hex(err);
	out_end();
}

/* A frame to the board itself: the register map through the transaction
 * module a TWI slave uses, never the bus; a write byte by byte as the slave
 * sees it, a read's n byte events in one call. The frame's bytes stay where
 * the parser put them: a write's data are handed over in place and a read's
 * answers land where the reply is made from. */
static uint8_t run_local(uint8_t addr, uint8_t *data, uint8_t n)
{
	uint8_t err = SG_OK;

	if (addr & 1) {
		/* n byte events at once: the answers are already where the
		 * reply is made from */
		if (!xact_read_requested(data, n) || !xact_read_take(n)) {
			err = SG_ERR_ADDR_NACK;
		}
		xact_frame_end();
		return err;
	}
	xact_write_requested(data + 1, n ? (uint8_t)(n - 1) : 0);
	/* the register byte, then the data in place at once */
	if (n && (!xact_write_select(data[0]) || !xact_write_taken((uint8_t)(n - 1)))) {
		err = SG_ERR_DATA_NACK;
	}
	if (xact_frame_end() != REG_OK) {
		err = SG_ERR_DATA_NACK;
	}
	return err;
}

static uint8_t run_bus(uint8_t addr, uint8_t *data, uint8_t n)
{
	twi_result_t r = twi_start(addr);
	if (r != TWI_ACK) {
		/* no ACK, or the bus could not be had (held, lost, timeout) */
		return SG_ERR_ADDR_NACK;
	}
	r = (addr & 1) ? twi_read_bytes(data, n) : twi_write_bytes(data, n);
	/* refused, or the bus was lost or stuck after the address was
	 * acknowledged */
	return r == TWI_ACK ? SG_OK : SG_ERR_DATA_NACK;
}

/* The gateway's own introspection read, `S AA 00 0N S AB 0M P` with N
 * within the count (the parser takes no read of 0 bytes): once the line is checked it cannot
 * fail (the write only moves the cursor, a read of the introspection
 * register always gives bytes), so its write frame's reply, `SWAA`, may
 * leave before the frames run (issue 20: the latency of driver info; at
 * 460800 baud its four characters cover most of the frames' run, where
 * the line stood idle ~600 cycles after the S alone in a back-to-back
 * burst). */
__attribute__((noinline)) static bool intro_read(const uint8_t *b, uint8_t nbytes)
{
	return b[0] == gate.local && (b[1] | b[2] << 8) == (2 | REGMAP_INTRO_REG << 8) &&
	       b[3] <= regmap_driver_count() && b[4] == (uint8_t)(gate.local | 1) &&
	       nbytes == (uint8_t)(6 + b[5]);
}

static void run_i2c(sg_parser_t *p)
{
	uint8_t *const end = p->buf + p->nbytes;
	uint8_t err = SG_OK;
	bool on_bus = false;
	uint8_t *reply = p->buf;  /* the first frame whose reply has not begun */

	if (intro_read(p->buf, p->nbytes)) {
		sg_out2('S', 'W');
		sg_out2('A', 'A');
		reply += 4;  /* the write frame [addr][2][register][N] */
	}

	/* frames as [addr][n][n bytes], walked with a pointer */
	for (uint8_t *f = p->buf; f < end && err == SG_OK;) {
		uint8_t addr = f[0];
		uint8_t n = f[1];
		uint8_t *data = f + 2;
		f = data + n;
		if ((uint8_t)(addr & 0xFE) == gate.local) {
			err = run_local(addr, data, n);
		} else {
			on_bus = true;
			err = run_bus(addr, data, n);
		}
	}
	/* A STOP that cannot be made leaves the last frame unfinished: its
	 * slave drops it (twi_quiet.h), so the request failed. */
	if (on_bus && !twi_stop() && err == SG_OK) {
		err = SG_ERR_DATA_NACK;
	}
	if (err != SG_OK) {
		out_error(err);
		return;
	}
	/* A request has a frame at least (the parser's): the reply's first
	 * byte leaves before anything else is looked at (or has left; with
	 * the frame's letter in one sg_out2() it left ~20 cycles later); after
	 * an early write frame's reply, from the read frame on. */
	uint8_t *f = reply;
	do {
		sg_out('S');
		uint8_t addr = f[0];
		uint8_t n = f[1];
		uint8_t *data = f + 2;
		f = data + n;
		sg_out((addr & 1) ? 'R' : 'W');
		if (addr & 1) {
			for (uint8_t k = 0; k < n; k++) {
				out_hex(data[k]);
			}
		} else {
			uint8_t k = n;
			for (; k > 1; k -= 2) {
				sg_out2('A', 'A');
			}
			if (k) {
				sg_out('A');
			}
		}
	} while (f < end);
	sg_out('P');
	out_end();
}

void sg_exec_lost(const sg_parser_t *p)
{
	for (uint16_t i = 0; i < p->lost; i++) {
		out_error(SG_ERR_DATA);
		sg_lost_answered();
	}
}

void sg_exec_init(void)
{
	xact_init();
	gate.local = SG_LOCAL_DEFAULT;
	gate.khz = twi_set_khz(SG_KHZ_DEFAULT);
}

void sg_exec(sg_parser_t *p)
{
	if (p->err != SG_OK) {
		out_error(p->err);
		return;
	}
	if (p->cmd == SG_CMD_I2C) {
		/* first: the requests whose latency counts */
		run_i2c(p);
		return;
	}
	switch (p->cmd) {
	case SG_CMD_VERSION:
		sg_out2('V', '1');
		sg_out2('.', '1');
		break;
	case SG_CMD_CLEAR:
		if (!twi_clear_bus()) {
			out_error(SG_ERR_ADDR_NACK);  /* the bus is still held */
			return;
		}
		sg_out('X');
		break;
	case SG_CMD_LOCAL:
		if (p->nbytes) {
			gate.local = p->buf[0] & 0xFE;
		}
		sg_out('L');
		out_hex(gate.local);
		break;
	case SG_CMD_CLOCK:
		if (p->nbytes) {
			gate.khz = twi_set_khz((uint16_t)(p->buf[0] << 8 | p->buf[1]));
		}
		sg_out('C');
		out_hex((uint8_t)(gate.khz >> 8));
		out_hex((uint8_t)gate.khz);
		break;
	default:
		out_error(SG_ERR_INTERNAL);
		return;
	}
	out_end();
}
