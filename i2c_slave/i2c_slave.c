/*
 * The I2C slave front end (MODE=slave): the TWI answers at ORFA_ADDR and
 * slave_fsm.c decides; this file only moves its decisions into TWCR/TWDR.
 * The interrupt does byte moves and quick checks only, with other
 * interrupts allowed; work that reaches a driver runs in
 * front_poll() while TWINT stays set, so the TWI holds SCL low (clock
 * stretching) and the master waits for it.
 */
#include "firmware/front.h"

#include <avr/interrupt.h>
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

/* Interrupt on, acknowledging: the TWI's resting state as a slave. */
#define SLAVE_TWCR (_BV(TWEN) | _BV(TWIE) | _BV(TWEA))

static volatile uint8_t slave_deferred;
/* Low byte of the clock tick of the last TWI event, or of the end of the
 * work it was deferred to (the master waited on us meanwhile). */
static volatile uint8_t slave_seen;

/* Has the open frame had no bus event for longer than a healthy master
 * leaves one? Its master abandoned it (twi_quiet.h). */
static bool slave_quiet(void)
{
	return slave_fsm_in_frame() &&
	       (uint8_t)(clock_now8() - slave_seen) > TWI_QUIET_DROP_TICKS;
}

static void slave_apply(slave_action_t act, uint8_t byte)
{
	switch (act) {
	case SLAVE_SEND:
		TWDR = byte;
		TWCR = _BV(TWINT) | SLAVE_TWCR;
		break;
	case SLAVE_NACK:
		TWCR = _BV(TWINT) | _BV(TWEN) | _BV(TWIE);
		break;
	case SLAVE_DEFER:
		/* TWINT not written: it stays set and SCL stays low. */
		slave_deferred = 1;
		TWCR = _BV(TWEN) | _BV(TWEA);
		break;
	case SLAVE_RECOVER:
		TWCR = _BV(TWINT) | _BV(TWSTO) | SLAVE_TWCR;
		break;
	default:
		TWCR = _BV(TWINT) | SLAVE_TWCR;
		break;
	}
}

/* Interruptible: the TWI's own interrupt is held off (TWIE clear) and
 * TWINT stays set, holding SCL, while other interrupts may come first (the
 * M32-D's cycle-exact servo edges must not wait for a bus byte). */
ISR(TWI_vect)
{
	/* TWIE off before interrupts are on again, or this one would come
	 * back at once: TWINT is a level. Writing TWINT 0 leaves it set. */
	TWCR = (uint8_t)(TWCR & ~(_BV(TWINT) | _BV(TWIE)));
	uint8_t now = clock_now8();
	uint8_t quiet = (uint8_t)(now - slave_seen);  /* ticks since the last event */
	slave_seen = now;
	sei();
	uint8_t byte = TWDR;
	uint8_t status = TW_STATUS;
	/* Its own address (SLA+W or SLA+R) keeps the link alive; frames for
	 * other addresses never reach here. */
	if (status == TW_SR_SLA_ACK || status == TW_ST_SLA_ACK) {
		SYS_HEARD();
	}
	/* The one event that applies a write (STOP or repeated START) ends
	 * a frame gone quiet, however soon the main loop would have looked:
	 * then it is dropped, not applied. (A START in the middle of a frame
	 * is a repeated START to this TWI.) */
	if (status == TW_SR_STOP && quiet > TWI_QUIET_DROP_TICKS) {
		slave_fsm_drop();
	}
	slave_action_t act = slave_fsm_event(status, &byte);
	cli();
	slave_apply(act, byte);
}

void front_init(void)
{
	slave_fsm_init();
	TWAR = ORFA_ADDR;  /* TWGCE (bit 0) off: no general call */
	TWCR = SLAVE_TWCR;
}

void front_poll(void)
{
	if (!slave_deferred) {
		/* A master gone in the middle of a frame must not leave this
		 * TWI addressed for good (a transmitter could hold SDA low):
		 * start again, the frame dropped (a write is not applied).
		 * Checked again with interrupts off: an event may just come. */
		if (slave_quiet()) {
			cli();
			if (slave_quiet()) {
				TWCR = 0;
				slave_fsm_drop();
				TWCR = SLAVE_TWCR;
			}
			sei();
		}
		sys_poll();  /* idle: the failsafe's turn */
		return;
	}
	/* The interrupt is off until slave_apply() turns it on again. */
	slave_deferred = 0;
	uint8_t byte = 0xFF;
	slave_action_t act = slave_fsm_work(&byte);
	slave_seen = clock_now8();
	slave_apply(act, byte);
}

/* No serial line: the TWI holds SCL while its interrupt waits. */
void front_rx_hold(void)
{
}

void front_rx_poll(uint8_t most)
{
	(void)most;
}
