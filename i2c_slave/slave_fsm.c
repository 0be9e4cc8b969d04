#include "i2c_slave/slave_fsm.h"

#include <util/twi.h>

#include "firmware/xact.h"

typedef enum {
	WORK_NONE = 0,
	WORK_FRAME_END,   /* end the frame: a write frame's data applied */
	WORK_WRITE_START, /* a write frame begins */
	WORK_READ_START,  /* a read frame's first driver answer */
	WORK_READ_MORE,   /* the driver's next answer */
} slave_work_t;

static struct {
	uint8_t buf[SLAVE_BUF_SIZE];
	uint8_t work;      /* slave_work_t deferred to the main loop */
	uint8_t in_write;  /* a write frame is open (TW_SR_STOP ends it) */
	uint8_t in_frame;  /* addressed, the frame not ended yet */
	uint8_t reading;   /* a read frame is open: slave_fsm_after() takes ahead */
	uint8_t next_ok;   /* `next` is the byte the master reads next */
	uint8_t next;
} slave;

/* No read frame open, nothing taken ahead. */
static inline __attribute__((always_inline)) void slave_no_read(void)
{
	slave.reading = 0;
	slave.next_ok = 0;
}

/* No frame open, nothing taken ahead. */
static void slave_idle(void)
{
	slave.work = WORK_NONE;
	slave.in_write = 0;
	slave.in_frame = 0;
	slave_no_read();
}

void slave_fsm_init(void)
{
	xact_init();
	slave_idle();
}

void slave_fsm_drop(void)
{
	xact_frame_drop();
	slave_idle();
}

bool slave_fsm_in_frame(void)
{
	return slave.in_frame;
}

static slave_action_t slave_defer(slave_work_t work)
{
	slave.work = work;
	return SLAVE_DEFER;
}

/* Ends an open write frame: a write with data needs its driver (deferred);
 * a bare register selection or a refused frame ends at once. */
static slave_action_t slave_end_write(void)
{
	slave.in_write = 0;
	if (xact_write_pending()) {
		slave.work = WORK_FRAME_END;
		return SLAVE_DEFER_ACK;  /* the write needs its driver, not the bus */
	}
	xact_frame_end();
	return SLAVE_ACK;
}

/* The read frame is over (or was never one): nothing to take ahead; the
 * bus goes on before its end is booked. */
static slave_action_t slave_end_read(void)
{
	slave_no_read();
	slave.work = WORK_FRAME_END;
	return SLAVE_DEFER_ACK;
}

bool slave_fsm_acks(uint8_t status)
{
	/* the sending statuses are TW_ST_SLA_ACK, TW_ST_ARB_LOST_SLA_ACK
	 * and TW_ST_DATA_ACK, in a row */
	return status != TW_SR_DATA_ACK && status != TW_BUS_ERROR &&
	       (uint8_t)(status - TW_ST_SLA_ACK) > TW_ST_DATA_ACK - TW_ST_SLA_ACK;
}

bool slave_fsm_ahead(uint8_t *byte)
{
	if (!slave.next_ok) {
		return false;
	}
	slave.next_ok = 0;
	*byte = slave.next;
	return true;
}

bool slave_fsm_received(uint8_t byte)
{
	slave.in_frame = 1;
	return xact_write_received(byte);
}

slave_action_t slave_fsm_event(uint8_t status, uint8_t *byte)
{
	/* The byte taken ahead first: the master waits for it, SCL held. */
	if (status == TW_ST_DATA_ACK && slave_fsm_ahead(byte)) {
		return SLAVE_SEND;
	}
	/* addressed until a frame's end: STOP or repeated START, a refused
	 * byte, the master's NACK or the last byte sent */
	slave.in_frame = 1;
	/* Then the two the master waits on longest, tested first. */
	if (status == TW_ST_SLA_ACK || status == TW_ST_ARB_LOST_SLA_ACK) {
		return slave_defer(WORK_READ_START);
	}
	if (status == TW_SR_DATA_ACK) {
		return slave_fsm_received(*byte) ? SLAVE_ACK : SLAVE_NACK;
	}
	switch (status) {
	case TW_SR_SLA_ACK:
	case TW_SR_ARB_LOST_SLA_ACK:
		/* acknowledged whatever comes: the frame is opened after */
		slave.in_write = 1;
		slave_no_read();
		slave.work = WORK_WRITE_START;
		return SLAVE_DEFER_ACK;
	case TW_ST_DATA_ACK:
		/* nothing taken ahead: the driver's answer is used up */
		if (!xact_read_buffered()) {
			return slave_defer(WORK_READ_MORE);
		}
		xact_read_processed(byte);
		return SLAVE_SEND;
	default:
		break;
	}
	slave.in_frame = 0;
	if (status == TW_SR_STOP) {
		/* the frame's end: the master waits to go on */
		return slave.in_write ? slave_end_write() : slave_end_read();
	}
	switch (status) {
	case TW_SR_DATA_NACK:
		/* Refused byte: the TWI is no longer addressed, and no STOP
		 * event will come for this frame. */
		return slave_end_write();
	case TW_ST_DATA_NACK:
	case TW_ST_LAST_DATA:
		return slave_end_read();
	case TW_BUS_ERROR:
		slave_fsm_drop();
		return SLAVE_RECOVER;
	default:
		/* General call is off (TWGCE = 0); nothing else is ours. */
		return SLAVE_ACK;
	}
}

void slave_fsm_read_start(uint8_t *byte)
{
	slave.in_frame = 1;
	slave.next_ok = 0;
	slave.reading = 1;
	/* the driver's answer goes to the buffer's start: its first byte
	 * taken where it is */
	*byte = xact_read_requested(slave.buf, sizeof slave.buf) && xact_read_take(1) ?
		slave.buf[0] : 0xFF;
}

slave_action_t slave_fsm_work(uint8_t *byte)
{
	slave_work_t work = (slave_work_t)slave.work;

	slave.work = WORK_NONE;
	if (work == WORK_READ_START) {
		/* first: the master waits for its byte, SCL held */
		slave_fsm_read_start(byte);
		return SLAVE_SEND;
	}
	switch (work) {
	case WORK_FRAME_END:
		xact_frame_end();
		return SLAVE_RESUME;
	case WORK_WRITE_START:
		xact_write_requested(slave.buf, sizeof slave.buf);
		return SLAVE_RESUME;
	case WORK_READ_MORE:
		xact_read_processed(byte);
		return SLAVE_SEND;
	default:
		return SLAVE_ACK;
	}
}

void slave_fsm_after(void)
{
	if (slave.reading && !slave.next_ok && slave.work == WORK_NONE && xact_read_buffered()) {
		xact_read_processed(&slave.next);
		slave.next_ok = 1;
	}
}
