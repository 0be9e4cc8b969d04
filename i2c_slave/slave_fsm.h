/*
 * The TWI slave's decisions (docs/registers.md, "On a slave board"), free of
 * hardware: one call per TWI event with its status code (avr-libc's TW_*
 * names), one action back for the thin layer in i2c_slave.c to put into
 * TWCR/TWDR. Host unit tests drive it with status sequences as the AVR TWI
 * produces them.
 *
 * What the hardware decides first, and what follows here:
 *  - a received byte is acknowledged before its value is seen, so a refusal
 *    (xact_write_received() false) clears TWEA: the byte AFTER it is not
 *    acknowledged, and the status register tells;
 *  - the own read address is always acknowledged: a register that cannot
 *    be read sends FF bytes, and the status register tells;
 *  - a write is applied when its frame ends (TW_SR_STOP: STOP or repeated
 *    START), all or nothing; a rejection then is told by the status only;
 *  - a frame its master abandons is dropped, never applied: on a bus error,
 *    and when the frame goes quiet (i2c_slave.c calls slave_fsm_drop()
 *    before the late event, twi_quiet.h).
 *
 * Work that calls a driver (applying a write, a driver's read answer) is
 * never done in the interrupt: the event returns SLAVE_DEFER, TWINT stays
 * set so the TWI stretches SCL, and the main loop calls slave_fsm_work().
 * Applying a write needs nothing of the bus: SLAVE_DEFER_ACK lets the bus
 * go on (the next address is acknowledged by the TWI alone) and holds the
 * next event until the write is applied. Everything else is a few byte
 * moves, with the bookkeeping after the answer (slave_fsm_after()).
 *
 * The polled layer (i2c_slave.c) takes the shortest way to each answer,
 * the master waiting with SCL held: the byte taken ahead
 * (slave_fsm_ahead()), a received byte's decision (slave_fsm_received()),
 * a read frame's first byte without the deferral (slave_fsm_read_start()),
 * and the answer first wherever the status alone decides it
 * (slave_fsm_acks()); each gives what slave_fsm_event() would.
 */
#ifndef SLAVE_FSM_H
#define SLAVE_FSM_H

#include <stdbool.h>
#include <stdint.h>

/* Bytes a write frame may carry and a driver may answer at once. */
#define SLAVE_BUF_SIZE 64

typedef enum {
	SLAVE_ACK = 0,  /* clear TWINT with TWEA: acknowledge what comes next */
	SLAVE_NACK,     /* clear TWINT without TWEA: refuse the next byte */
	SLAVE_SEND,     /* TWDR = *byte, then clear TWINT with TWEA */
	SLAVE_DEFER,    /* keep TWINT (SCL held low), turn the interrupt off;
			 * the main loop calls slave_fsm_work() */
	SLAVE_RECOVER,  /* bus error: TWSTO releases the lines, then as ACK */
	SLAVE_DEFER_ACK, /* as SLAVE_ACK at once, but the interrupt stays off:
			  * the main loop calls slave_fsm_work(), which says
			  * SLAVE_RESUME (the next event waits, SCL held, until
			  * then) */
	SLAVE_RESUME,   /* from slave_fsm_work() after SLAVE_DEFER_ACK: the
			 * interrupt on again, TWINT as it is */
} slave_action_t;

void slave_fsm_init(void);

/* The master abandoned the frame in progress (it went quiet: twi_quiet.h):
 * dropped, a write in it not applied, the status says so. Also a bus
 * error's doing. */
void slave_fsm_drop(void);

/* True when the answer to an event with this status is SLAVE_ACK or
 * SLAVE_DEFER_ACK whatever came before (a frame's end, its own write
 * address, what is never ours): the TWI layer may let the bus go on
 * first and call slave_fsm_event() after. False for a byte received (its
 * value decides), the statuses that send and a bus error. */
bool slave_fsm_acks(uint8_t status);

/* A byte of a write frame received (a TW_SR_DATA_ACK event, as
 * slave_fsm_event() takes it): true to acknowledge the next one
 * (SLAVE_ACK), false to refuse it (SLAVE_NACK). */
bool slave_fsm_received(uint8_t byte);

/* A read frame begins (TW_ST_SLA_ACK, TW_ST_ARB_LOST_SLA_ACK): the
 * driver's answer asked for at once, its first byte in *byte to send (as
 * slave_fsm_event()'s SLAVE_DEFER and slave_fsm_work()'s SLAVE_SEND give
 * it, for a layer that need not defer). */
void slave_fsm_read_start(uint8_t *byte);

/* The byte the master reads next (a TW_ST_DATA_ACK event), if
 * slave_fsm_after() took it ahead: true and *byte, to send at once; the
 * event is then answered (slave_fsm_event() would say SLAVE_SEND). */
bool slave_fsm_ahead(uint8_t *byte);

/* A TWI event: `status` is TW_STATUS; `*byte` holds TWDR for received
 * data and receives the byte to send for SLAVE_SEND. */
slave_action_t slave_fsm_event(uint8_t status, uint8_t *byte);

/* True while the TWI is addressed in a frame that has not ended (no STOP,
 * repeated START, refused byte or last byte yet). */
bool slave_fsm_in_frame(void);

/* The deferred work of the last SLAVE_DEFER or SLAVE_DEFER_ACK; returns
 * SLAVE_SEND (with *byte) to release the bus with, or SLAVE_RESUME. */
slave_action_t slave_fsm_work(uint8_t *byte);

/* After each answer, once the bus has it (the TWI's interrupt still off):
 * in a read frame the byte the master reads next is taken ahead from what
 * the driver answered already (never a driver call), so that its event
 * sends it at once. */
void slave_fsm_after(void);

#endif
