/*
 * twi_arb_master.c: a TWI master that is also a slave, for the simulator's
 * arbitration tests (tests/sim/test_bus_faults_midbyte.py), not ORFA
 * firmware.
 *
 * Its TWI answers at OWN_ADDR (8-bit form) and to the general call
 * (TWGCE) with TWEA set all along. Each
 * time PB0 goes low (the test drives it) it sends a START and the next
 * address of TARGETS, TWEA kept set, and puts in PORTA the status the TWI
 * gives after it (0x18/0x20/0x40/0x48, or 0x38, 0x68, 0x78, 0xB0 when it
 * lost arbitration there). As master it then sends a STOP; addressed as a slave
 * it answers one byte (0xFF for a read, a write's byte refused) and so
 * leaves the frame; after 0x38 it lets the bus go. Between triggers it
 * acknowledges what it gets as a slave, and puts each status but the
 * frame's end (0xA0) in PORTA. PORTC counts the triggers done.
 */
#include <avr/io.h>
#include <stdint.h>
#include <util/twi.h>

#define OWN_ADDR 0x1E
/* 0x20 with its bit 2 lost reads 0x1F: a read from OWN_ADDR (0xB0); a read
 * from OWN_ADDR with its bit 7 lost reads 0x1E: a write to it (0x68); 0x20
 * again (nobody there: 0x20, then a STOP); 0x10 with its bit 3 lost reads
 * 0x0F (nobody: 0x38); 0x01 with its bit 7 lost reads 0x00, the general
 * call (0x78). */
static const uint8_t TARGETS[] = { 0x20, 0x1F, 0x20, 0x10, 0x01 };

#define GO (_BV(TWINT) | _BV(TWEA) | _BV(TWEN))

static uint8_t twi_wait(void)
{
	while (!(TWCR & _BV(TWINT))) {
	}
	return TW_STATUS;
}

int main(void)
{
	uint8_t n = 0;

	DDRA = 0xFF;
	DDRC = 0xFF;
	PORTB = _BV(PB0);	/* pulled up until the test drives it */
	TWBR = 32;		/* 100 kHz at 7.3728 MHz */
	TWAR = OWN_ADDR | 1;	/* TWGCE: the general call too */
	TWCR = _BV(TWEA) | _BV(TWEN);
	for (;;) {
		while (PINB & _BV(PB0)) {
			/* a slave's leftovers (0xA0 after 0x68: the next START
			 * ends that frame): acknowledged, the bus let go */
			if (TWCR & _BV(TWINT)) {
				if (TW_STATUS != TW_SR_STOP) {
					PORTA = TW_STATUS;
				}
				TWCR = GO;
			}
		}
		TWCR = GO | _BV(TWSTA);
		twi_wait();
		TWDR = TARGETS[n % sizeof TARGETS];
		TWCR = GO;
		uint8_t st = twi_wait();
		PORTA = st;
		switch (st) {
		case TW_ST_ARB_LOST_SLA_ACK:
			/* the last byte, all 1s: SDA stays free (the rival
			 * clocks nothing out of it) */
			TWDR = 0xFF;
			TWCR = _BV(TWINT) | _BV(TWEN);
			break;
		case TW_SR_ARB_LOST_SLA_ACK:
		case TW_SR_ARB_LOST_GCALL_ACK:
			TWCR = _BV(TWINT) | _BV(TWEN);	/* refuse its byte */
			break;
		case TW_MT_ARB_LOST:
			TWCR = GO;	/* the bus released, not addressed */
			break;
		default:
			TWCR = GO | _BV(TWSTO);
			while (TWCR & _BV(TWSTO)) {
			}
			break;
		}
		PORTC = ++n;
		while (!(PINB & _BV(PB0))) {
		}
	}
}
