#include "firmware/twi_master.h"

#include <avr/io.h>
#include <avr/wdt.h>
#include <util/delay.h>
#include <util/twi.h>

#include "board.h"
#include "firmware/mcu.h"
#include "firmware/twi_rate.h"

/* Cycles of one twi_wait() polling loop at least (avr-gcc 5.4 -Os: 9 on
 * the ATmega32, 10 on the ATmega128, more with interrupts). */
#define TWI_LOOP_CYCLES 9
/* The longest SCL stretch a slave is waited for: an ORFA slave holds SCL
 * while it applies a write; the longest is an SPI exchange of the 60 bytes a
 * request can carry at the slowest SPI clock (F_CPU/128: 1024 cycles a
 * byte), about 8.5 ms with the servo interrupts; 16 servo triples on an
 * M32-D take about 5.6 ms. Interrupts only make a loop longer. */
#define TWI_STRETCH_MAX_US 12000UL
#define TWI_STRETCH_LOOPS \
	(TWI_STRETCH_MAX_US * (F_CPU / 1000UL) / (1000UL * TWI_LOOP_CYCLES))

static struct {
	uint32_t timeout;  /* polling loops before a step counts as hung */
} twi;

void twi_init(void)
{
	TWCR = _BV(TWEN);
	twi_set_khz(100);
}

uint16_t twi_set_khz(uint16_t khz)
{
	twi_rate_t r = twi_rate_for_khz(F_CPU, khz);
	TWBR = r.twbr;
	TWSR = r.twps;  /* only the prescaler bits are writable */
	/* A polling loop takes at least TWI_LOOP_CYCLES: 3 periods of loops
	 * cover a whole byte (9 periods) twice over; on top, the time a slave
	 * may stretch SCL (an ORFA slave applies a write while it holds SCL). */
	twi.timeout = 3 * r.period + 256 + TWI_STRETCH_LOOPS;
	return r.khz;
}

/* Waits for TWINT; false on timeout. */
static bool twi_wait(void)
{
	uint32_t n = twi.timeout;
	while (!(TWCR & _BV(TWINT))) {
		if (--n == 0) {
			return false;
		}
	}
	wdt_reset();  /* a slow bus makes progress: don't let the watchdog bite */
	return true;
}

twi_result_t twi_start(uint8_t addr8)
{
	TWCR = _BV(TWINT) | _BV(TWSTA) | _BV(TWEN);
	if (!twi_wait() || (TW_STATUS != TW_START && TW_STATUS != TW_REP_START)) {
		return TWI_FAIL;
	}
	TWDR = addr8;
	TWCR = _BV(TWINT) | _BV(TWEN);
	if (!twi_wait()) {
		return TWI_FAIL;
	}
	switch (TW_STATUS) {
	case TW_MT_SLA_ACK:
	case TW_MR_SLA_ACK:
		return TWI_ACK;
	case TW_MT_SLA_NACK:
	case TW_MR_SLA_NACK:
		return TWI_NACK;
	default:
		return TWI_FAIL;
	}
}

twi_result_t twi_write(uint8_t byte)
{
	TWDR = byte;
	TWCR = _BV(TWINT) | _BV(TWEN);
	if (!twi_wait()) {
		return TWI_FAIL;
	}
	switch (TW_STATUS) {
	case TW_MT_DATA_ACK:
		return TWI_ACK;
	case TW_MT_DATA_NACK:
		return TWI_NACK;
	default:
		return TWI_FAIL;
	}
}

twi_result_t twi_read(uint8_t *byte, bool ack)
{
	TWCR = _BV(TWINT) | _BV(TWEN) | (ack ? _BV(TWEA) : 0);
	if (!twi_wait()) {
		return TWI_FAIL;
	}
	*byte = TWDR;
	uint8_t want = ack ? TW_MR_DATA_ACK : TW_MR_DATA_NACK;
	return TW_STATUS == want ? TWI_ACK : TWI_FAIL;
}

void twi_stop(void)
{
	TWCR = _BV(TWINT) | _BV(TWSTO) | _BV(TWEN);
	uint32_t n = twi.timeout;
	while (TWCR & _BV(TWSTO)) {
		if (--n == 0) {
			/* The TWI is wedged: restart it. */
			TWCR = 0;
			TWCR = _BV(TWEN);
			return;
		}
	}
}

/* Open-drain lines by hand: low = output 0, released = input with pull-up. */
static void line_low(const mcu_port_t *p, uint8_t bit)
{
	*p->port &= (uint8_t)~bit;
	*p->ddr |= bit;
}

static void line_release(const mcu_port_t *p, uint8_t bit)
{
	*p->ddr &= (uint8_t)~bit;
	*p->port |= bit;
}

void twi_clear_bus(void)
{
	mcu_port_t port = mcu_port(BOARD_TWI_PORT - 'A');
	const mcu_port_t *p = &port;
	const uint8_t scl = _BV(BOARD_TWI_SCL);
	const uint8_t sda = _BV(BOARD_TWI_SDA);

	TWCR = 0;  /* the pins become ordinary port pins */
	line_release(p, scl);
	line_release(p, sda);
	_delay_us(5);
	for (uint8_t i = 0; i < 9 && !(*p->pin & sda); i++) {
		line_low(p, scl);
		_delay_us(5);
		line_release(p, scl);
		_delay_us(5);
	}
	/* STOP: SDA rises while SCL is high. */
	line_low(p, scl);
	line_low(p, sda);
	_delay_us(5);
	line_release(p, scl);
	_delay_us(5);
	line_release(p, sda);
	_delay_us(5);
	/* Back to the TWI, pins as after reset. */
	*p->port &= (uint8_t)~(scl | sda);
	TWCR = _BV(TWEN);
}
