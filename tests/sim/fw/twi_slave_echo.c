/*
 * twi_slave_echo.c: a tiny interrupt-driven TWI slave for the simulator's
 * bus tests (tests/sim/test_twi_slave.py), not ORFA firmware.
 *
 * It answers at ECHO_ADDR (8-bit form). A write frame's data bytes are kept
 * (up to 16; a 17th is not acknowledged); a read frame gives them back in
 * order, then again from the first. Before the first byte of every read it
 * waits ECHO_STRETCH cycles with TWINT set, so the bus shows a clock
 * stretch the tests can measure.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>
#include <util/twi.h>

#ifndef ECHO_ADDR
#define ECHO_ADDR 0x20
#endif
#define ECHO_STRETCH 1500
#define ECHO_SIZE 16

static uint8_t buf[ECHO_SIZE];
static uint8_t len, idx;

/* TWEA: acknowledge the next byte (and our address once idle again). */
#define ECHO_GO (_BV(TWINT) | _BV(TWEA) | _BV(TWEN) | _BV(TWIE))

ISR(TWI_vect)
{
	uint8_t cr = ECHO_GO;

	switch (TW_STATUS) {
	case TW_SR_SLA_ACK:
		len = 0;
		break;
	case TW_SR_DATA_ACK:
		buf[len++] = TWDR;
		if (len == ECHO_SIZE) {
			cr &= (uint8_t)~_BV(TWEA);	/* buffer full: NACK the next */
		}
		break;
	case TW_ST_SLA_ACK:
		__builtin_avr_delay_cycles(ECHO_STRETCH);
		idx = 0;
		/* fall through */
	case TW_ST_DATA_ACK:
		TWDR = len ? buf[idx] : 0xEE;
		idx = (uint8_t)(len ? (idx + 1) % len : 0);
		break;
	default:
		/* 0x88, 0xA0, 0xC0, 0xC8: addressable again */
		break;
	}
	TWCR = cr;
}

int main(void)
{
	TWAR = ECHO_ADDR;
	TWCR = ECHO_GO;
	sei();
	for (;;) {
	}
}
