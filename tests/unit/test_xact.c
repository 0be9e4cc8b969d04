/*
 * The transaction module (firmware/xact.c) with this board's real drivers:
 * byte-at-a-time frames as a TWI slave makes them (no read length known,
 * a 64-byte buffer) must give exactly what the gateway's frames give (the
 * read length known, the request's own bytes as the buffer), for random
 * frame sequences; and the refusals docs/registers.md ("On a slave board")
 * describes land where it says.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <util/twi.h>

#include "drv_test.h"
#include "firmware/xact.h"
#include "i2c_slave/slave_fsm.h"
#include "xact_model.h"

static uint8_t status_read(void)
{
	uint8_t buf[SLAVE_BUF], st = 0xEE;
	xact_write_requested(buf, sizeof buf);
	xact_write_received(REGMAP_STATUS_REG);
	xact_frame_end();
	xact_read_requested(buf, sizeof buf);
	xact_read_processed(&st);
	xact_frame_end();
	return st;
}

static uint32_t rng_state;

static uint32_t rnd(uint32_t n)
{
	rng_state = rng_state * 1103515245u + 12345u;
	return (rng_state >> 8) % n;
}

/* Mostly plausible frames for this board's registers, some garbage. */
static void random_frame(frame_t *f)
{
	memset(f, 0, sizeof *f);
	f->reg = (uint8_t)(rnd(4) ? rnd(B.nregs) : rnd(256));
	f->read = (uint8_t)(rnd(2));
	if (f->read) {
		f->n = (uint8_t)(1 + (rnd(3) ? rnd(16) : rnd(SLAVE_BUF)));
		return;
	}
	f->n = (uint8_t)(rnd(3) ? rnd(8) : rnd(SLAVE_BUF + 1));
	for (uint8_t k = 0; k < f->n; k++) {
		f->data[k] = (uint8_t)(rnd(3) ? rnd(4) : rnd(256));
	}
	if (f->reg == B.servo_sp && rnd(2)) {
		/* whole triples: channel, width */
		f->n = (uint8_t)(3 * (1 + rnd(5)));
		for (uint8_t k = 0; k < f->n; k += 3) {
			uint16_t w = (uint16_t)(rnd(3000));
			f->data[k] = (uint8_t)rnd(B.servo_channels + 1);
			f->data[k + 1] = (uint8_t)(w >> 8);
			f->data[k + 2] = (uint8_t)w;
		}
	}
}

static void test_equal_to_frames(void)
{
	enum { ROUNDS = 300, FRAMES = 40 };
	static frame_t seq[FRAMES];
	static result_t a[FRAMES], b[FRAMES], c[FRAMES], sa[FRAMES], sb[FRAMES], sc[FRAMES];
	static result_t d[FRAMES], sd[FRAMES];
	unsigned reads = 0;
	int bad = 0;

	rng_state = 12345;
	for (int round = 0; round < ROUNDS; round++) {
		for (unsigned i = 0; i < FRAMES; i++) {
			random_frame(&seq[i]);
		}
		xact_model_run(seq, FRAMES, a, sa, xact_model_gateway);
		xact_model_run(seq, FRAMES, b, sb, xact_model_slave);
		xact_model_run(seq, FRAMES, c, sc, xact_model_twi);
		xact_model_run(seq, FRAMES, d, sd, xact_model_local);
		/* The gateway's one call for a frame's data (what sg_exec.c
		 * runs) against its bytes one at a time: the same answer, the
		 * same status, the same state after (each frame's result in a
		 * sequence); its acks are all or none. */
		for (unsigned i = 0; i < FRAMES && !bad; i++) {
			result_t want = a[i], swant = sa[i];
			if (!seq[i].read && want.acks != 1 + seq[i].n) {
				want.acks = 0;
			}
			if (seq[i].read && swant.acks != 1) {
				swant.acks = 0;
			}
			if (memcmp(&want, &d[i], sizeof want) != 0 ||
			    memcmp(&swant, &sd[i], sizeof swant) != 0) {
				printf("xact local round %d frame %u (%s reg %02X n %u): bytes acks %u "
				       "end %02X st %02X, one call acks %u end %02X st %02X\n", round, i,
				       seq[i].read ? "read" : "write", seq[i].reg, seq[i].n, want.acks,
				       want.end, want.status, d[i].acks, d[i].end, d[i].status);
				bad = 1;
			}
		}
		for (unsigned i = 0; i < FRAMES; i++) {
			sa[i].end = sb[i].end = sc[i].end = 0;  /* in the status too */
			reads += seq[i].read && a[i].ok && seq[i].reg > REGMAP_STATUS_REG;
			if (memcmp(&sa[i], &sb[i], sizeof sa[i]) != 0 ||
			    memcmp(&sa[i], &sc[i], sizeof sa[i]) != 0) {
				printf("xact fuzz round %d frame %u: the selects differ\n", round, i);
				bad = 1;
			}
		}
		for (unsigned i = 0; i < FRAMES && !bad; i++) {
			if (memcmp(&a[i], &b[i], sizeof a[i]) != 0) {
				printf("xact fuzz round %d frame %u (%s reg %02X n %u): gateway "
				       "acks %u end %02X st %02X ok %u got %02X.., slave acks %u "
				       "end %02X st %02X ok %u got %02X..\n",
				       round, i, seq[i].read ? "read" : "write", seq[i].reg,
				       seq[i].n, a[i].acks, a[i].end, a[i].status, a[i].ok,
				       a[i].got[0], b[i].acks, b[i].end, b[i].status, b[i].ok,
				       b[i].got[0]);
				bad = 1;
			}
		}
		for (unsigned i = 0; i < FRAMES && !bad; i++) {
			/* the TWI run has no frame-end result (the status has
			 * it), and sends FF where the gateway refuses a read */
			result_t want = a[i];
			want.end = 0;
			c[i].end = 0;
			if (seq[i].read) {
				if (!want.ok) {
					memset(want.got, 0xFF, seq[i].n);
				}
				want.ok = 1;
			}
			if (memcmp(&want, &c[i], sizeof want) != 0) {
				printf("twi fuzz round %d frame %u (%s reg %02X n %u): gateway acks %u "
				       "st %02X ok %u, twi slave acks %u st %02X ok %u\n", round, i,
				       seq[i].read ? "read" : "write", seq[i].reg, seq[i].n, a[i].acks,
				       a[i].status, a[i].ok, c[i].acks, c[i].status, c[i].ok);
				bad = 1;
			}
		}
	}
	CHECK(!bad);
	/* the reads reached drivers, not only the status register */
	CHECK(reads > ROUNDS * FRAMES / 4);
}

static void test_refusals(void)
{
	uint8_t buf[4], byte;

	boot();
	xact_init();
	/* An unmapped register byte: refused, so is the rest; status 08. */
	xact_write_requested(buf, sizeof buf);
	CHECK(!xact_write_received(B.nregs));
	CHECK(!xact_write_received(0x00));
	CHECK_EQ(xact_frame_end(), REG_NO_REGISTER);
	/* ... and no register is selected: a read gives FF, the status
	 * keeps 08, until a register byte names one. */
	CHECK(!xact_read_requested(buf, sizeof buf));
	CHECK(!xact_read_processed(&byte));
	CHECK_EQ(byte, 0xFF);
	CHECK_EQ(xact_frame_end(), REG_OK);
	CHECK_EQ(status_read(), REG_NO_REGISTER);
	/* Data for the status register: the first data byte is refused. */
	xact_write_requested(buf, sizeof buf);
	CHECK(xact_write_received(REGMAP_STATUS_REG));
	CHECK(!xact_write_received(0x00));
	CHECK_EQ(xact_frame_end(), REG_NOT_WRITABLE);
	CHECK_EQ(status_read(), REG_NOT_WRITABLE);
	/* More data than the buffer: refused at the first byte beyond it,
	 * and nothing applied (the servo SP write of two triples = 6 bytes). */
	xact_write_requested(buf, sizeof buf);
	CHECK(xact_write_received(B.servo_sp));
	CHECK(xact_write_received(0x00));
	CHECK(xact_write_received(0x05));
	CHECK(xact_write_received(0xDC));
	CHECK(xact_write_received(0x01));
	CHECK(!xact_write_received(0x05));
	CHECK_EQ(xact_frame_end(), REG_BAD_LENGTH);
	READ(B.servo_sp, 4, "00 00 00 00");
	/* A data byte that makes the write invalid (a servo channel that
	 * does not exist): refused at once, the rest too (docs/registers.md, "On a
	 * slave board"). */
	xact_write_requested(buf, sizeof buf);
	CHECK(xact_write_received(B.servo_sp));
	CHECK(!xact_write_received(B.servo_channels));
	CHECK(!xact_write_received(0x05));
	CHECK_EQ(xact_frame_end(), REG_BAD_VALUE);
	CHECK_EQ(status_read(), REG_BAD_VALUE);
	/* A write found wrong only when it ends (two bytes of a triple):
	 * acknowledged byte by byte, rejected at the end, status tells. */
	xact_write_requested(buf, sizeof buf);
	CHECK(xact_write_received(B.servo_sp));
	CHECK(xact_write_received(0x00));
	CHECK(xact_write_received(0x05));
	CHECK_EQ(xact_frame_end(), REG_BAD_LENGTH);
	CHECK_EQ(status_read(), REG_BAD_LENGTH);
	/* A register that cannot be read (SPI DATA before any exchange):
	 * nothing, FF bytes, status 05. */
	xact_write_requested(buf, sizeof buf);
	CHECK(xact_write_received(B.spi_data));
	CHECK_EQ(xact_frame_end(), REG_OK);
	xact_read_requested(buf, sizeof buf);
	CHECK(!xact_read_processed(&byte));
	CHECK_EQ(byte, 0xFF);
	CHECK_EQ(xact_frame_end(), REG_OK);
	CHECK_EQ(status_read(), REG_NOT_READABLE);
	/* Bytes outside a frame: refused, FF. */
	CHECK(!xact_write_received(0x00));
	CHECK(!xact_read_processed(&byte));
	CHECK_EQ(byte, 0xFF);
}

/* Introspection through a slave's buffer: the count stays, records move
 * one per record given, never more than the master takes plus one. */
static void test_intro_cursor(void)
{
	uint8_t buf[SLAVE_BUF], b, cnt;
	boot();
	xact_init();
	xact_read_requested(buf, sizeof buf);
	CHECK(xact_read_processed(&cnt));
	CHECK_EQ(cnt, B.ndrivers);
	CHECK(xact_read_processed(&b));
	CHECK_EQ(b, B.ndrivers);
	xact_frame_end();
	xact_read_requested(buf, sizeof buf);
	CHECK(xact_read_processed(&b));
	CHECK_EQ(b, B.ndrivers);
	xact_frame_end();
	/* driver 2, 3 bytes of it; the next read starts at driver 3 */
	uint8_t sel[1];
	xact_write_requested(sel, sizeof sel);
	xact_write_received(0x00);
	xact_write_received(0x02);
	CHECK_EQ(xact_frame_end(), REG_OK);
	xact_read_requested(buf, sizeof buf);
	for (int i = 0; i < 3; i++) {
		xact_read_processed(&b);
	}
	xact_frame_end();
	xact_read_requested(buf, sizeof buf);
	uint8_t rec[6];
	for (int i = 0; i < 6; i++) {
		xact_read_processed(&rec[i]);
	}
	xact_frame_end();
	CHECK_EQ(rec[4], 0x02 + B.gpio_nports * 2);  /* driver 3 = SPI starts after GPIO */
}

/* A driver's check never refuses what its write would take: for random
 * writes to every register (introspection too), with an SPI channel bound so
 * that exchanges can succeed, a write refused at byte k is rejected whole by
 * the driver at every length from k on (each from the same fresh state). */
static void test_check_agrees_with_write(void)
{
	uint8_t data[SLAVE_BUF];
	int bad = 0, taken = 0;
	/* SPI channel 0's chip select: C2 on the M32-D, A2 on the M128-S */
	const uint8_t bind[3] = { 0x00, (uint8_t)(B.gpio_nports == 4 ? 2 : 0), 0x02 };

	rng_state = 777;
	for (int round = 0; round < 20000 && !bad; round++) {
		uint8_t reg = (uint8_t)(rnd(4) ? 2 + rnd(B.nregs - 2) : 0);
		uint8_t n = (uint8_t)(1 + (rnd(2) ? rnd(6) : rnd(SLAVE_BUF)));
		for (uint8_t k = 0; k < n; k++) {
			data[k] = (uint8_t)(rnd(2) ? rnd(3) : rnd(256));
		}
		if (reg == B.spi_data && rnd(2)) {
			data[0] = 0;  /* the bound channel */
		}
		boot();
		bad |= !regmap_select(B.spi_config) || regmap_write(bind, 3) != REG_OK;
		bad |= !regmap_select(reg);
		uint8_t refused_at = 0;
		for (uint8_t k = 1; k <= n && !refused_at; k++) {
			if (regmap_check(data, k) != REG_OK) {
				refused_at = k;
			}
		}
		for (uint8_t m = refused_at ? refused_at : n; m <= n && !bad; m++) {
			boot();
			bad |= !regmap_select(B.spi_config) || regmap_write(bind, 3) != REG_OK;
			bad |= !regmap_select(reg);
			reg_status_t st = regmap_write(data, m);
			taken += st == REG_OK;
			if (refused_at && st == REG_OK) {
				printf("check refused register %02X at byte %u, the write took %u\n",
				       reg, refused_at, m);
				bad = 1;
			}
		}
	}
	CHECK(!bad);
	CHECK(taken > 1000);  /* the writes were not all refused anyway */
}

/* The slave addressed for writing, then each byte given, every one
 * acknowledged: a write frame as a master begins it. */
static void slave_write_at(const char *file, int line, const uint8_t *data, size_t n)
{
	uint8_t b = 0;
	check_eq_at(file, line, xact_model_twi_event(TW_SR_SLA_ACK, &b), SLAVE_ACK,
		    "SLA+W's answer");
	for (size_t i = 0; i < n; i++) {
		b = data[i];
		check_eq_at(file, line, xact_model_twi_event(TW_SR_DATA_ACK, &b), SLAVE_ACK,
			    "a data byte's answer");
	}
}
#define SLAVE_WRITE(...) slave_write_at(__FILE__, __LINE__, (const uint8_t[]){ __VA_ARGS__ }, \
					sizeof (const uint8_t[]){ __VA_ARGS__ })

/* A master that gives up mid-frame: a bus error (illegal START/STOP) drops
 * the frame whole; a read that a STOP ends without a NACK leaves the slave
 * ready for the next frame. */
static void test_aborted_frames(void)
{
	uint8_t b;

	boot();
	slave_fsm_init();
	uint8_t sp = B.servo_sp;
	SLAVE_WRITE(sp, 0x00, 0x05, 0xDC);
	CHECK_EQ(xact_model_twi_event(TW_BUS_ERROR, &b), SLAVE_RECOVER);
	CHECK_EQ(regmap_status(), REG_DROPPED);
	READ(sp, 2, "00 00");                    /* nothing applied */
	/* A frame gone quiet (twi_quiet.h): i2c_slave.c drops it before the
	 * late event that ends it (the next request's START: TW_SR_STOP),
	 * which then applies nothing. */
	SLAVE_WRITE(sp, 0x00, 0x05, 0xDC);
	CHECK(slave_fsm_in_frame());
	slave_fsm_drop();
	CHECK(!slave_fsm_in_frame());
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	CHECK_EQ(regmap_status(), REG_DROPPED);
	READ(sp, 2, "00 00");
	/* a bare register selection dropped: the selection stands, the
	 * status is not touched */
	SLAVE_WRITE(sp);
	slave_fsm_drop();
	CHECK_EQ(regmap_status(), REG_OK);
	/* the next frame is served: the same write, ended properly */
	SLAVE_WRITE(sp, 0x00, 0x05, 0xDC);
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	READ(sp, 2, "05 DC");
	/* a read the master ends with a STOP after an ACK: no event comes
	 * (the TWI leaves the frame by itself); the next write is served.
	 * (READ above left the status register selected: select SP.) */
	SLAVE_WRITE(sp);
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	CHECK_EQ(xact_model_twi_event(TW_ST_SLA_ACK, &b), SLAVE_SEND);
	CHECK_EQ(b, 0x05);
	CHECK_EQ(xact_model_twi_event(TW_ST_DATA_ACK, &b), SLAVE_SEND);
	CHECK_EQ(b, 0xDC);
	SLAVE_WRITE(sp, 0x00, 0x00, 0x00);
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	READ(sp, 2, "00 00");
	/* No register selected after an unmapped one, also across a bus
	 * error: a read gives FF, the status keeps 08. */
	SLAVE_WRITE(0x00);
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	CHECK_EQ(xact_model_twi_event(TW_SR_SLA_ACK, &b), SLAVE_ACK);
	b = 0xFE;
	CHECK_EQ(xact_model_twi_event(TW_SR_DATA_ACK, &b), SLAVE_NACK);
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	CHECK_EQ(xact_model_twi_event(TW_ST_SLA_ACK, &b), SLAVE_SEND);
	CHECK_EQ(b, 0xFF);
	CHECK_EQ(xact_model_twi_event(TW_ST_DATA_NACK, &b), SLAVE_ACK);
	CHECK_EQ(xact_model_twi_event(TW_BUS_ERROR, &b), SLAVE_RECOVER);
	CHECK_EQ(xact_model_twi_event(TW_ST_SLA_ACK, &b), SLAVE_SEND);
	CHECK_EQ(b, 0xFF);
	CHECK_EQ(xact_model_twi_event(TW_ST_DATA_NACK, &b), SLAVE_ACK);
	CHECK_EQ(regmap_status(), REG_NO_REGISTER);
}

/* Bus faults in the middle of a byte (docs/protocol.md, the bus-fault
 * table): the slave's TWI gives 0x00 wherever the illegal START or STOP
 * falls, and the frame is dropped whole; a slave addressed by a master that
 * won arbitration against this TWI (0x68, 0xB0) serves the frame as
 * after 0x60, 0xA8. */
static void test_faults_mid_byte(void)
{
	uint8_t b;

	boot();
	slave_fsm_init();
	uint8_t sp = B.servo_sp;
	/* in the register byte: nothing had arrived, the status stands */
	CHECK_EQ(xact_model_twi_event(TW_SR_SLA_ACK, &b), SLAVE_ACK);
	CHECK_EQ(xact_model_twi_event(TW_BUS_ERROR, &b), SLAVE_RECOVER);
	CHECK(!slave_fsm_in_frame());
	CHECK_EQ(regmap_status(), REG_OK);
	/* in the middle of a read: the frame ends, nothing else changes */
	SLAVE_WRITE(sp, 0x00, 0x05, 0xDC);
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	SLAVE_WRITE(sp);
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	CHECK_EQ(xact_model_twi_event(TW_ST_SLA_ACK, &b), SLAVE_SEND);
	CHECK_EQ(b, 0x05);
	CHECK(slave_fsm_in_frame());
	CHECK_EQ(xact_model_twi_event(TW_BUS_ERROR, &b), SLAVE_RECOVER);
	CHECK(!slave_fsm_in_frame());
	CHECK_EQ(regmap_status(), REG_OK);
	/* after the last data byte, before the STOP: dropped, not applied */
	SLAVE_WRITE(sp, 0x00, 0x07, 0xD0);
	CHECK_EQ(xact_model_twi_event(TW_BUS_ERROR, &b), SLAVE_RECOVER);
	CHECK_EQ(regmap_status(), REG_DROPPED);
	READ(sp, 2, "05 DC");
	/* the arbitration-lost entries: a write applied at its STOP ... */
	CHECK_EQ(xact_model_twi_event(TW_SR_ARB_LOST_SLA_ACK, &b), SLAVE_ACK);
	CHECK(slave_fsm_in_frame());
	const uint8_t data[] = { sp, 0x00, 0x06, 0x40 };
	for (unsigned i = 0; i < sizeof data; i++) {
		b = data[i];
		CHECK_EQ(xact_model_twi_event(TW_SR_DATA_ACK, &b), SLAVE_ACK);
	}
	CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	CHECK_EQ(regmap_status(), REG_OK);
	/* ... and a read served from the selected register */
	CHECK_EQ(xact_model_twi_event(TW_ST_ARB_LOST_SLA_ACK, &b), SLAVE_SEND);
	CHECK_EQ(b, 0x06);
	CHECK_EQ(xact_model_twi_event(TW_ST_DATA_ACK, &b), SLAVE_SEND);
	CHECK_EQ(b, 0x40);
	CHECK_EQ(xact_model_twi_event(TW_ST_DATA_NACK, &b), SLAVE_ACK);
	CHECK(!slave_fsm_in_frame());
}

/* The statuses whose answer i2c_slave.c gives before the event: all but
 * a byte received, the three that send and a bus error (xact_model.c checks
 * the answer of each event that comes). */
static void test_acks_first(void)
{
	for (unsigned st = 0; st < 0x100; st += 8) {
		int decides = st == TW_SR_DATA_ACK || st == TW_ST_SLA_ACK ||
			      st == TW_ST_ARB_LOST_SLA_ACK || st == TW_ST_DATA_ACK ||
			      st == TW_BUS_ERROR;
		CHECK_EQ(slave_fsm_acks((uint8_t)st), !decides);
	}
}

void xact_tests(void)
{
	test_acks_first();
	test_aborted_frames();
	test_faults_mid_byte();
	test_check_agrees_with_write();
	test_refusals();
	test_intro_cursor();
	test_equal_to_frames();
}
