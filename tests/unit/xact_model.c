/* The three ways of a register frame into firmware/xact.c (xact_model.h). */
#include "xact_model.h"

#include <string.h>

#include <util/twi.h>

#include "drv_test.h"
#include "firmware/xact.h"

/* The status register's value, without selecting register 01 (so a read
 * frame of the fuzz reads the register its own select named). */
uint8_t xact_model_status(void)
{
	return (uint8_t)regmap_status();
}

/* The gateway's way (serialgate/sg_exec.c run_local): the frame's bytes are
 * the buffer, the read length is known, a read's bytes are taken at once
 * (xact_read_take: n byte events in one call). A write frame is [reg][data], so its
 * select is part of it; a read frame reads the selected register. */
void xact_model_gateway(const frame_t *f, result_t *r)
{
	uint8_t bytes[1 + SLAVE_BUF];
	memset(r, 0, sizeof *r);
	if (f->read) {
		/* all n byte events at once, as the gateway takes them */
		r->ok = xact_read_requested(r->got, f->n) && xact_read_take(f->n);
		if (!r->ok) {
			memset(r->got, 0, sizeof r->got);
		}
	} else {
		bytes[0] = f->reg;
		memcpy(bytes + 1, f->data, f->n);
		xact_write_requested(bytes + 1, f->n);
		for (uint8_t k = 0; k <= f->n && xact_write_received(bytes[k]); k++) {
			r->acks++;
		}
	}
	r->end = xact_frame_end();
	r->status = xact_model_status();
}

void xact_model_local(const frame_t *f, result_t *r)
{
	uint8_t bytes[1 + SLAVE_BUF];
	if (f->read) {
		xact_model_gateway(f, r);  /* the same calls */
		return;
	}
	memset(r, 0, sizeof *r);
	bytes[0] = f->reg;
	memcpy(bytes + 1, f->data, f->n);
	xact_write_requested(bytes + 1, f->n);
	if (xact_write_select(bytes[0]) && xact_write_taken(f->n)) {
		r->acks = (uint8_t)(1 + f->n);
	}
	r->end = xact_frame_end();
	r->status = xact_model_status();
}

/* The slave's way (i2c_slave/): its own 64-byte buffer, bytes one at a time
 * with no length known; the master stops after n. */
void xact_model_slave(const frame_t *f, result_t *r)
{
	static uint8_t buf[SLAVE_BUF];
	memset(r, 0, sizeof *r);
	if (f->read) {
		r->ok = xact_read_requested(buf, sizeof buf);
		for (uint8_t k = 0; k < f->n && r->ok; k++) {
			r->ok = xact_read_processed(&r->got[k]);
		}
		if (!r->ok) {
			memset(r->got, 0, sizeof r->got);
		}
	} else {
		xact_write_requested(buf, sizeof buf);
		if (xact_write_received(f->reg)) {
			r->acks++;
			for (uint8_t k = 0; k < f->n && xact_write_received(f->data[k]); k++) {
				r->acks++;
			}
		}
	}
	r->end = xact_frame_end();
	r->status = xact_model_status();
}

/* The whole slave (i2c_slave/slave_fsm.c) under a model of the AVR TWI: the
 * status codes the hardware gives for a master's frame, TWEA deciding the
 * next byte's acknowledge, deferred work done as the main loop would. */
slave_action_t xact_model_twi_event(uint8_t status, uint8_t *byte)
{
	/* i2c_slave.c's ways: the byte taken ahead sent at once; a read
	 * frame's first byte asked for at once (every other time here, the
	 * deferred way of slave_fsm_event() the others); an answer known
	 * from the status alone given before the event */
	static unsigned turn;
	if (status == TW_ST_DATA_ACK && slave_fsm_ahead(byte)) {
		slave_fsm_after();
		return SLAVE_SEND;
	}
	if ((status == TW_ST_SLA_ACK || status == TW_ST_ARB_LOST_SLA_ACK) && turn++ % 2) {
		slave_fsm_read_start(byte);
		slave_fsm_after();
		return SLAVE_SEND;
	}
	int acks = slave_fsm_acks(status);
	slave_action_t act = slave_fsm_event(status, byte);
	CHECK(!acks || act == SLAVE_ACK || act == SLAVE_DEFER_ACK);
	if (act == SLAVE_DEFER) {
		act = slave_fsm_work(byte);
	} else if (act == SLAVE_DEFER_ACK) {
		/* acknowledged at once; the next event waits for the work */
		CHECK_EQ(slave_fsm_work(byte), SLAVE_RESUME);
		act = SLAVE_ACK;
	}
	slave_fsm_after();
	return act;
}

void xact_model_twi(const frame_t *f, result_t *r)
{
	uint8_t b = 0;
	memset(r, 0, sizeof *r);
	if (f->read) {
		int sent_ok = xact_model_twi_event(TW_ST_SLA_ACK, &b) == SLAVE_SEND;
		CHECK(slave_fsm_in_frame());
		r->got[0] = b;
		for (uint8_t k = 1; k < f->n; k++) {
			sent_ok &= xact_model_twi_event(TW_ST_DATA_ACK, &b) == SLAVE_SEND;
			r->got[k] = b;
		}
		sent_ok &= xact_model_twi_event(TW_ST_DATA_NACK, &b) == SLAVE_ACK;
		CHECK(sent_ok);
		CHECK(!slave_fsm_in_frame());  /* the master's NACK ends it */
		r->status = xact_model_status();
		r->ok = 1;  /* the TWI cannot refuse: compared as FF bytes */
		return;
	}
	CHECK_EQ(xact_model_twi_event(TW_SR_SLA_ACK, &b), SLAVE_ACK);
	CHECK(slave_fsm_in_frame());
	int twea = 1, addressed = 1;
	for (uint8_t k = 0; k <= f->n && addressed; k++) {
		b = k ? f->data[k - 1] : f->reg;
		if (!twea) {
			/* the byte after a refusal is not acknowledged, and the
			 * TWI leaves the frame */
			CHECK_EQ(xact_model_twi_event(TW_SR_DATA_NACK, &b), SLAVE_ACK);
			addressed = 0;
			break;
		}
		twea = xact_model_twi_event(TW_SR_DATA_ACK, &b) == SLAVE_ACK;
		r->acks = (uint8_t)(r->acks + twea);
	}
	if (addressed) {
		CHECK(slave_fsm_in_frame());
		CHECK_EQ(xact_model_twi_event(TW_SR_STOP, &b), SLAVE_ACK);
	}
	/* a STOP or a refused byte ends the frame (the slave's stall timer) */
	CHECK(!slave_fsm_in_frame());
	r->status = xact_model_status();
}

void xact_model_run(const frame_t *seq, unsigned n, result_t *out, result_t *sel_out,
		    void (*run)(const frame_t *, result_t *))
{
	boot();
	xact_init();
	slave_fsm_init();
	for (unsigned i = 0; i < n; i++) {
		memset(&sel_out[i], 0, sizeof sel_out[i]);
		if (seq[i].read) {
			frame_t sel = { .reg = seq[i].reg, .read = 0, .n = 0 };
			run(&sel, &sel_out[i]);
		}
		run(&seq[i], &out[i]);
	}
}
