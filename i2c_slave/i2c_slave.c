/*
 * The I2C slave front end (MODE=slave): the TWI answers at ORFA_ADDR and
 * slave_fsm.c decides; this file only moves its decisions into TWCR/TWDR.
 * The main loop polls the TWI (TWINT) and answers each event there: while
 * TWINT is set the TWI holds SCL low (clock stretching) and the master
 * waits, so the sooner the answer, the sooner the bus goes on. Polled, an
 * answer costs no interrupt entry and exit (a TWI interrupt saved and
 * restored 20 registers around every byte) and other interrupts (the
 * M32-D's cycle-exact servo edges) are never held off by a bus byte. The
 * main loop has nothing else to do but the link-loss failsafe.
 */
#include "firmware/front.h"

#include <avr/io.h>
#include <util/twi.h>

#include "firmware/clock.h"
#include "firmware/i2c_addr.h"
#include "firmware/sys.h"
#include "firmware/twi_quiet.h"
#include "i2c_slave/slave_fsm.h"

#ifndef ORFA_ADDR
#error "ORFA_ADDR: the slave's 8-bit bus address (make ADDR=0x10)"
#endif

_Static_assert((ORFA_ADDR & 1) == 0, "ADDR is the 8-bit form: even");
_Static_assert(I2C_ADDR_OK(ORFA_ADDR), "ADDR is an I2C reserved address (firmware/i2c_addr.h)");

/* Enabled, acknowledging its address, no interrupt: the TWI's resting
 * state as a slave. */
#define SLAVE_TWCR (_BV(TWEN) | _BV(TWEA))

/* Low byte of the clock tick of the last TWI event, or of the end of the
 * work it needed (the master waited on us meanwhile). */
static uint8_t slave_seen;

/* No bus event for longer than a healthy master leaves between two? */
static bool slave_quiet_since(void)
{
	return (uint8_t)(clock_now8() - slave_seen) > TWI_QUIET_DROP_TICKS;
}

/* Has the open frame gone so quiet? Its master abandoned it
 * (twi_quiet.h). */
static bool slave_quiet(void)
{
	return slave_fsm_in_frame() && slave_quiet_since();
}

/* TWCR answers: TWINT written 1 lets the bus go on; TWEA acknowledges
 * what comes next. */
#define SLAVE_GO_ON (_BV(TWINT) | SLAVE_TWCR)
#define SLAVE_REFUSE_NEXT (_BV(TWINT) | _BV(TWEN))

/* The answer into TWDR/TWCR (SLAVE_ACK, SLAVE_NACK, SLAVE_SEND or
 * SLAVE_RECOVER: the others are answered before their work). */
static void slave_apply(slave_action_t act, uint8_t byte)
{
	/* the common answers tested first */
	if (act == SLAVE_SEND) {
		TWDR = byte;
		TWCR = SLAVE_GO_ON;
	} else if (act == SLAVE_ACK) {
		TWCR = SLAVE_GO_ON;
	} else if (act == SLAVE_NACK) {
		TWCR = SLAVE_REFUSE_NEXT;
	} else {
		TWCR = _BV(TWINT) | _BV(TWSTO) | SLAVE_TWCR;
	}
}

/* One TWI event (TWINT set), answered: as soon as its answer is known,
 * the bookkeeping after. */
static void slave_event(void)
{
	uint8_t status = TW_STATUS;
	uint8_t byte, next;

	if (status == TW_ST_DATA_ACK && slave_fsm_ahead(&next)) {
		/* the common read byte, taken ahead: sent at once */
		TWDR = next;
		TWCR = SLAVE_GO_ON;
		slave_seen = clock_now8();
		slave_fsm_after();
		return;
	}
	if (status == TW_SR_DATA_ACK) {
		/* a byte received: its value decides the next one's
		 * acknowledge */
		TWCR = slave_fsm_received(TWDR) ? SLAVE_GO_ON : SLAVE_REFUSE_NEXT;
	} else if (status == TW_ST_SLA_ACK || status == TW_ST_ARB_LOST_SLA_ACK) {
		/* a read frame: its first byte is the driver's, the master
		 * waits for it (SCL held) */
		slave_fsm_read_start(&byte);
		TWDR = byte;
		TWCR = SLAVE_GO_ON;
	} else {
		/* A frame's end, the own write address, a read byte not taken
		 * ahead, a bus error. Where the status alone decides the
		 * answer (acknowledged whatever the state) the bus goes on
		 * first: the next event waits in TWINT until this one's work
		 * is done. */
		bool first = slave_fsm_acks(status);
		if (first) {
			TWCR = SLAVE_GO_ON;
		}
		/* The one event that applies a write (STOP or repeated
		 * START) ends a frame gone quiet, however soon it comes
		 * after the quiet spell: then it is dropped, not applied. (A
		 * START in the middle of a frame is a repeated START to this
		 * TWI.) */
		if (status == TW_SR_STOP && slave_quiet_since()) {
			slave_fsm_drop();
		}
		byte = TWDR;
		slave_action_t act = slave_fsm_event(status, &byte);
		if (act == SLAVE_DEFER) {
			/* a driver's read answer: SCL held meanwhile */
			act = slave_fsm_work(&byte);
		}
		if (act == SLAVE_DEFER_ACK) {
			/* answered first: a write applied while the bus goes on */
			slave_fsm_work(&byte);
		} else if (!first) {
			slave_apply(act, byte);
		}
	}
	slave_seen = clock_now8();
	/* Its own address (SLA+W or SLA+R) keeps the link alive; frames for
	 * other addresses never reach here. Booked at once: the main loop
	 * may go from event to event for a while. */
	if (status == TW_SR_SLA_ACK || status == TW_ST_SLA_ACK) {
		SYS_HEARD();
		sys_poll();
	}
	slave_fsm_after();
}

void front_init(void)
{
	slave_fsm_init();
	TWAR = ORFA_ADDR;  /* TWGCE (bit 0) off: no general call */
	TWCR = SLAVE_TWCR;
}

void front_poll(void)
{
	/* TWINT first and often: a bus event waits for nothing else. The
	 * failsafe and the quiet check count clock ticks, so they are looked
	 * at once a tick, right after it (the keep-alive is booked by the
	 * event itself). The wait reads TWCR and the clock and changes
	 * nothing: an idle board's simulator can skip it (docs/simulator.md,
	 * "Parked boards"). */
	uint8_t tick = clock_now8();
	do {
		/* four looks a turn: the clock's load costs one look's time */
		if ((TWCR & _BV(TWINT)) || (TWCR & _BV(TWINT)) ||
		    (TWCR & _BV(TWINT)) || (TWCR & _BV(TWINT))) {
			slave_event();
			return;
		}
	} while (clock_now8() == tick);
	if (tick == slave_seen) {
		/* an event in the tick just over: the bus may be busy, the
		 * master waiting for the next answer; the idle work waits for
		 * a tick without one */
		return;
	}
	/* A master gone in the middle of a frame must not leave this TWI
	 * addressed for good (a transmitter could hold SDA low): start
	 * again, the frame dropped (a write is not applied). */
	if (slave_quiet()) {
		TWCR = 0;
		slave_fsm_drop();
		TWCR = SLAVE_TWCR;
	}
	sys_poll();  /* idle: the failsafe's turn */
}

/* No serial line: the TWI holds SCL while its interrupt waits. */
void front_rx_hold(void)
{
}

front_rx_left_t front_rx_poll(uint8_t most)
{
	(void)most;
#ifdef BOARD_RX_BURST
	return 0;  /* no receiver: nothing held */
#endif
}

void front_rx_held(void)
{
}
