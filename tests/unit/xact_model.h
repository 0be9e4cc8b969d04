/*
 * The three ways a register frame reaches the transaction module
 * (firmware/xact.c), for differential tests: the gateway's (read length
 * known, the request's bytes as the buffer), a slave's byte by byte (a
 * 64-byte buffer, no length known), and the whole slave (i2c_slave/
 * slave_fsm.c) under a model of the AVR TWI. Shared by tests/unit/test_xact.c
 * and the fuzz harness tests/fuzz/fuzz_xact.c. A model step that goes wrong
 * reports through check_at() (drv_test.h), which each program provides.
 */
#ifndef UNIT_XACT_MODEL_H
#define UNIT_XACT_MODEL_H

#include <stdint.h>

#include "i2c_slave/slave_fsm.h"

#define SLAVE_BUF 64

typedef struct {
	uint8_t reg;
	uint8_t read;        /* read frame of n bytes, else write frame */
	uint8_t n;           /* read count, or data bytes after the register */
	uint8_t data[SLAVE_BUF];
} frame_t;

/* What a frame gave: acknowledges, bytes read, the result at its end. */
typedef struct {
	uint8_t acks;        /* bytes acknowledged, register byte included */
	uint8_t got[SLAVE_BUF];
	uint8_t ok;          /* read: register could be read */
	uint8_t end;         /* xact_frame_end() */
	uint8_t status;      /* the status register afterwards */
} result_t;

/* The status register's value, without selecting register 01 (so a read
 * frame reads the register its own select named). */
uint8_t xact_model_status(void);

/* The gateway's way before it took a write frame's data in one call: the
 * bytes in place, one xact_write_received() each (acks: where a refusal
 * lands, as a slave's). */
void xact_model_gateway(const frame_t *f, result_t *r);

/* The gateway's way now (serialgate/sg_exec.c run_local): the register
 * byte with xact_write_select(), the data in place with one
 * xact_write_taken(); acks: all of the frame's bytes or none (the gateway
 * replies all or an error). */
void xact_model_local(const frame_t *f, result_t *r);

/* A slave's way: its own buffer, bytes one at a time. */
void xact_model_slave(const frame_t *f, result_t *r);

/* One TWI event into slave_fsm, deferred work done at once as the main
 * loop would (SCL is held meanwhile, so no other event comes between). */
slave_action_t xact_model_twi_event(uint8_t status, uint8_t *byte);

/* The whole slave: the TWI status codes a master's frame makes. */
void xact_model_twi(const frame_t *f, result_t *r);

/* One of the ways above over n frames from power-on (boot(), which each
 * program provides, then the transaction module and the slave state
 * machine afresh). A read frame reads its register: the select runs first
 * as a write frame of its own, its result in sel_out, as a host sends it. */
void xact_model_run(const frame_t *seq, unsigned n, result_t *out, result_t *sel_out,
		    void (*run)(const frame_t *, result_t *));

#endif
