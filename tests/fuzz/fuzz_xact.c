/*
 * Harness fuzz-xact-<board>: the slave's byte-at-a-time transaction path,
 * firmware/xact.c and i2c_slave/slave_fsm.c, over the board's real drivers
 * (tests/unit/hw_fakes.c). The first byte of the input chooses:
 *
 * bit 0 clear: frames. The rest is a list of register frames
 *   [reg][flags: bit 0 read, bits 1-7 length][data...]; the sequence runs
 *   three ways from power-on, as tests/unit/test_xact.c runs its random
 *   ones (tests/unit/xact_model.c): the gateway's, a slave's byte by byte,
 *   and the whole slave under a model of the AVR TWI. All three must give
 *   the same acknowledges, bytes and status register (the TWI sending FF
 *   where the gateway refuses a read, as docs/registers.md, "On a slave board", says).
 *
 * bit 0 set: TWI events. Each byte is a master's action (START+SLA+W, a
 *   data byte, STOP, START+SLA+R, a read with ACK, a read with NACK, a bus
 *   error), turned into the status codes the AVR TWI gives (repeated
 *   STARTs, the NACKed byte after a refusal and the frame it ends included);
 *   with bit 1 of the first byte also any status code at all. Checked: the
 *   slave answers each event as the TWI needs (an address and data are
 *   acknowledged or refused, a read address always gets a byte to send, a
 *   bus error recovers), and after any of it, a bus error and an
 *   introspection read give the driver count: the slave is not stuck.
 */
#include <string.h>

#include <util/twi.h>

#include "drv_test.h"
#include "firmware/xact.h"
#include "fuzz.h"
#include "xact_model.h"

#define FRAMES_MAX 48

static fuzz_input_t in;

/* --- frames, three ways ---------------------------------------------------- */

static frame_t seq[FRAMES_MAX];
static result_t res[3][FRAMES_MAX], sel[3][FRAMES_MAX];

static void frames(uint8_t nregs)
{
	unsigned n = 0;
	while (in.left && n < FRAMES_MAX) {
		frame_t *f = &seq[n++];
		uint8_t r = fuzz_byte(&in), flags = fuzz_byte(&in);
		memset(f, 0, sizeof *f);
		f->reg = (r & 0x80) ? r : (uint8_t)(r % (nregs + 1));
		f->read = flags & 1;
		f->n = f->read ? (uint8_t)(1 + (flags >> 1) % SLAVE_BUF)
			       : (uint8_t)((flags >> 1) % (SLAVE_BUF + 1));
		for (uint8_t k = 0; k < f->n && !f->read; k++) {
			f->data[k] = fuzz_byte(&in);
		}
	}
	xact_model_run(seq, n, res[0], sel[0], xact_model_gateway);
	xact_model_run(seq, n, res[1], sel[1], xact_model_slave);
	xact_model_run(seq, n, res[2], sel[2], xact_model_twi);
	for (unsigned i = 0; i < n; i++) {
		const frame_t *f = &seq[i];
		sel[0][i].end = sel[1][i].end = sel[2][i].end = 0;  /* in the status too */
		FUZZ_REQUIRE(memcmp(&sel[0][i], &sel[1][i], sizeof sel[0][i]) == 0 &&
			     memcmp(&sel[0][i], &sel[2][i], sizeof sel[0][i]) == 0,
			     "frame %u: the selects of register %02X differ", i, f->reg);
		const result_t *a = &res[0][i], *b = &res[1][i];
		FUZZ_REQUIRE(memcmp(a, b, sizeof *a) == 0,
			     "frame %u (%s reg %02X n %u): gateway acks %u end %02X st %02X ok %u "
			     "got %02X.., slave acks %u end %02X st %02X ok %u got %02X..", i,
			     f->read ? "read" : "write", f->reg, f->n, a->acks, a->end, a->status,
			     a->ok, a->got[0], b->acks, b->end, b->status, b->ok, b->got[0]);
		/* the TWI run has no frame-end result (the status has it), and
		 * sends FF where the gateway refuses a read */
		result_t want = *a, *c = &res[2][i];
		want.end = 0;
		c->end = 0;
		if (f->read) {
			if (!want.ok) {
				memset(want.got, 0xFF, f->n);
			}
			want.ok = 1;
		}
		FUZZ_REQUIRE(memcmp(&want, c, sizeof want) == 0,
			     "frame %u (%s reg %02X n %u): gateway acks %u st %02X ok %u got %02X.., "
			     "twi slave acks %u st %02X ok %u got %02X..", i, f->read ? "read" : "write",
			     f->reg, f->n, a->acks, a->status, a->ok, a->got[0], c->acks, c->status,
			     c->ok, c->got[0]);
	}
}

/* --- TWI events ------------------------------------------------------------ */

static struct {
	int chaos;   /* any status code may come: no promises on the answers */
	int in_sr;   /* addressed for writing */
	int in_st;   /* addressed for reading */
	int twea;    /* the next received byte will be acknowledged */
} t;

static slave_action_t event(uint8_t status, uint8_t byte_in, int want_mask)
{
	uint8_t b = byte_in;
	slave_action_t act = xact_model_twi_event(status, &b);
	FUZZ_REQUIRE(t.chaos || (want_mask >> act & 1),
		     "TWI status %02X: the slave answered %d", status, act);
	return act;
}

#define A(x) (1 << (x))

/* A repeated START ends the frame in progress first. */
static void end_frame(void)
{
	if (t.in_sr) {
		event(TW_SR_STOP, 0, A(SLAVE_ACK));
	}
	if (t.in_st) {
		event(TW_ST_DATA_NACK, 0, A(SLAVE_ACK));  /* the master NACKs its last byte */
	}
	t.in_sr = t.in_st = 0;
}

static void twi_events(uint8_t chaos)
{
	boot();
	slave_fsm_init();
	memset(&t, 0, sizeof t);
	t.chaos = chaos;
	while (in.left) {
		uint8_t op = fuzz_byte(&in);
		switch (op % (t.chaos ? 8 : 7)) {
		case 0:
			end_frame();
			event((op & 8) ? TW_SR_ARB_LOST_SLA_ACK : TW_SR_SLA_ACK, 0, A(SLAVE_ACK));
			t.in_sr = t.twea = 1;
			break;
		case 1: {
			uint8_t b = fuzz_byte(&in);
			if (!t.in_sr) {
				break;  /* not addressed: the TWI says nothing */
			}
			if (!t.twea) {
				event(TW_SR_DATA_NACK, b, A(SLAVE_ACK));
				t.in_sr = 0;
				break;
			}
			t.twea = event(TW_SR_DATA_ACK, b, A(SLAVE_ACK) | A(SLAVE_NACK)) == SLAVE_ACK;
			break;
		}
		case 2:
			/* STOP: only a write frame hears it; a read the master
			 * stops after an ACK just ends */
			if (t.in_sr) {
				event(TW_SR_STOP, 0, A(SLAVE_ACK));
			}
			t.in_sr = t.in_st = 0;
			break;
		case 3:
			end_frame();
			event((op & 8) ? TW_ST_ARB_LOST_SLA_ACK : TW_ST_SLA_ACK, 0, A(SLAVE_SEND));
			t.in_st = 1;
			break;
		case 4:
			if (t.in_st) {
				event(TW_ST_DATA_ACK, 0, A(SLAVE_SEND));
			}
			break;
		case 5:
			if (t.in_st) {
				event((op & 8) ? TW_ST_LAST_DATA : TW_ST_DATA_NACK, 0, A(SLAVE_ACK));
			}
			t.in_st = 0;
			break;
		case 6:
			event(TW_BUS_ERROR, 0, A(SLAVE_RECOVER));
			t.in_sr = t.in_st = 0;
			break;
		default: {
			uint8_t status = fuzz_byte(&in), b = fuzz_byte(&in);
			event((uint8_t)(status & 0xF8), b, 0);
			t.in_sr = t.in_st = 0;
			break;
		}
		}
		fuzz_board_fixed_check();
		hw_log_clear();
	}
	/* not stuck: a bus error, then the driver count by introspection */
	t.chaos = 0;
	event(TW_BUS_ERROR, 0, A(SLAVE_RECOVER));
	frame_t f = { .reg = REGMAP_INTRO_REG, .read = 0, .n = 1, .data = { 0 } };
	result_t r;
	xact_model_twi(&f, &r);
	FUZZ_REQUIRE(r.acks == 2 && r.status == REG_OK, "introspection write: %u acks, status %02X",
		     r.acks, r.status);
	f.read = 1;
	xact_model_twi(&f, &r);
	FUZZ_REQUIRE(r.got[0] == regmap_driver_count(), "introspection count %02X, want %02X",
		     r.got[0], regmap_driver_count());
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size == 0) {
		return 0;
	}
	in = (fuzz_input_t){ data + 1, size - 1 };
	if (data[0] & 1) {
		twi_events(data[0] & 2);
	} else {
		boot();
		frames(fuzz_board_nregs());
	}
	return 0;
}
