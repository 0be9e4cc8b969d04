#include "firmware/twi_master.h"

#include <avr/io.h>
#include <avr/wdt.h>
#include <util/twi.h>

#include "board.h"
#include "firmware/clock.h"
#include "firmware/mcu.h"
#include "firmware/twi_quiet.h"
#include "firmware/twi_rate.h"

/* How long one step waits for the bus: a slave may stretch SCL while it
 * applies a write, the longest an SPI exchange of 57 bytes at F_CPU/128
 * while the M32-D's servo interrupts take their cycles (58368 cycles of SPI;
 * 60576-65938 over a servo frame's phases, measured in the simulator:
 * docs/protocol.md; 32 ticks were too few for some phases). On top, the
 * step's own bus time (twi_set_khz). A wait ends more than TWI_WAIT_TICKS
 * and at most one tick more after it began: 9.4-9.7 ms at 100 kHz and
 * faster, the most that still leaves a tick (0.28 ms) for the rest of the
 * request and its reply within 10 ms. */
#define TWI_WAIT_TICKS 34
_Static_assert((TWI_WAIT_TICKS + 2) * CLOCK_TICK_CYCLES <= F_CPU / 100,
	       "the wait, its phase and a tick for the reply within 10 ms");

static struct {
	uint8_t ticks;     /* clock ticks a step may take before it has failed */
	uint8_t quiet;     /* the quiet fence is up (twi_quiet.h) */
	uint8_t open;      /* a START of ours is on the bus, no STOP yet */
	uint16_t quiet_t0; /* clock_now() when it went up */
} twi;

/* Nothing of ours on the bus until the fence is down: a frame this board
 * gave up on, or may have been in when it reset, is dropped by its slave
 * first (twi_quiet.h). Out of line: twi_abandon() and twi_init(), off the
 * fast path, each had it inlined (8 bytes). */
static __attribute__((noinline)) void twi_fence_up(void)
{
	twi.quiet = 1;
	twi.quiet_t0 = clock_now();
}

/* Is the fence still up? It comes down by itself when its time is over,
 * looked at here and from the idle loop (twi_idle), so the 16-bit clock's
 * wrap (18.2 s) never makes an old fence look new. */
static bool twi_fence_is_up(void)
{
	if (twi.quiet && (uint16_t)(clock_now() - twi.quiet_t0) > TWI_QUIET_FENCE_TICKS) {
		twi.quiet = 0;
	}
	return twi.quiet;
}

static void twi_fence_wait(void)
{
	while (twi_fence_is_up()) {
	}
}

void twi_idle(void)
{
	(void)twi_fence_is_up();
}

/* The transaction is given up without a STOP (that would make a slave
 * apply a frame cut short): the TWI off and on again (TWBR/TWPS stay), the
 * lines released, the fence up. */
static twi_result_t twi_abandon(void)
{
	TWCR = 0;
	TWCR = _BV(TWEN);
	twi.open = 0;
	twi_fence_up();
	return TWI_FAIL;
}

void twi_init(void)
{
	TWCR = _BV(TWEN);
	/* The rate is the front end's to set (sg_exec_init: the one
	 * default, SG_KHZ_DEFAULT), before any transfer. */
	/* This board may have reset in the middle of a frame. */
	twi_fence_up();
}

uint16_t twi_set_khz(uint16_t khz)
{
	twi_rate_t r = twi_rate_for_khz(F_CPU, khz);
	TWBR = r.twbr;
	TWSR = r.twps;  /* only the prescaler bits are writable */
	/* On top of TWI_WAIT_TICKS, 8 SCL periods (period >> 8 ticks): a
	 * byte takes 9, the ninth fits in TWI_WAIT_TICKS with the short
	 * stretch a slave makes before a read; the long one (a write being
	 * applied) delays a START or STOP, one period. At most 34 + 127
	 * ticks (TWBR 255, TWPS 3): below 256. */
	twi.ticks = (uint8_t)(TWI_WAIT_TICKS + (r.period >> 8));
	return r.khz;
}

/* Waits until the TWCR bits in `mask` read `want`, within the bound. A step
 * that gets nowhere abandons the transaction, so the next request starts
 * clean. The watchdog is fed only when the bus made progress: a wait that
 * never ends cannot keep a hung board alive. */
static inline __attribute__((always_inline)) bool twi_wait_here(uint8_t mask, uint8_t want)
{
	uint8_t t0 = clock_now8();
	while ((TWCR & mask) != want) {
		if ((uint8_t)(clock_now8() - t0) > twi.ticks) {
			twi_abandon();
			return false;
		}
	}
	wdt_reset();
	return true;
}

static bool twi_wait_for(uint8_t mask, uint8_t want)
{
	return twi_wait_here(mask, want);
}

/* Waits for TWINT; false on timeout. */
static bool twi_wait(void)
{
	return twi_wait_for(_BV(TWINT), _BV(TWINT));
}

/* Sends a byte (an address or data) and waits for its acknowledgement
 * (or its absence); false on timeout, as twi_wait(). */
static bool twi_send(uint8_t byte)
{
	TWDR = byte;
	TWCR = _BV(TWINT) | _BV(TWEN);
	return twi_wait();
}

twi_result_t twi_start(uint8_t addr8)
{
	twi_fence_wait();
	TWCR = _BV(TWINT) | _BV(TWSTA) | _BV(TWEN);
	if (!twi_wait()) {
		return TWI_FAIL;
	}
	if (TW_STATUS != TW_START && TW_STATUS != TW_REP_START) {
		return twi_abandon();
	}
	twi.open = 1;
	if (!twi_send(addr8)) {
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
		/* arbitration lost, a bus error */
		return twi_abandon();
	}
}

/* The bytes of a frame loop here, each the next step as soon as the last
 * one's TWINT is seen: a slave's bus time counts every cycle between two
 * (make bench, "bus time % of wire"). */
twi_result_t twi_write_bytes(const uint8_t *data, uint8_t n)
{
	for (; n; n--) {
		if (!twi_send(*data++)) {
			return TWI_FAIL;
		}
		uint8_t st = TW_STATUS;
		if (st != TW_MT_DATA_ACK) {
			return st == TW_MT_DATA_NACK ? TWI_NACK : twi_abandon();
		}
	}
	return TWI_ACK;
}

twi_result_t twi_read_bytes(uint8_t *data, uint8_t n)
{
	while (n) {
		/* acknowledged but the last: the slave sends no more */
		uint8_t cr = _BV(TWINT) | _BV(TWEN) | _BV(TWEA);
		uint8_t want = TW_MR_DATA_ACK;
		if (!--n) {
			cr = _BV(TWINT) | _BV(TWEN);
			want = TW_MR_DATA_NACK;
		}
		TWCR = cr;
		/* waited for here, not through a call: the next byte's step
		 * follows TWINT sooner */
		if (!twi_wait_here(_BV(TWINT), _BV(TWINT))) {
			return TWI_FAIL;
		}
		*data++ = TWDR;
		if (TW_STATUS != want) {
			return twi_abandon();
		}
	}
	return TWI_ACK;
}

bool twi_stop(void)
{
	if (!twi.open) {
		return true;  /* nothing of ours on the bus (given up already) */
	}
	twi.open = 0;
	TWCR = _BV(TWINT) | _BV(TWSTO) | _BV(TWEN);
	return twi_wait_for(_BV(TWSTO), 0);
}

/* Open-drain lines by hand: low = output 0, released = input with pull-up.
 * Inlined on the TWI port known when compiling: a bit is one sbi/cbi. */
static inline __attribute__((always_inline)) void line_low(const mcu_port_t *p, uint8_t bit)
{
	*p->port &= (uint8_t)~bit;
	*p->ddr |= bit;
}

static inline __attribute__((always_inline)) void line_release(const mcu_port_t *p, uint8_t bit)
{
	*p->ddr &= (uint8_t)~bit;
	*p->port |= bit;
}

/* Half an SCL period of the clearing (5 us), the call's 7 cycles (rcall,
 * ret) included: one call, not a delay loop inlined at each of six places
 * (26 bytes). */
#define TWI_HALF_CLOCK_CYCLES ((uint16_t)((F_CPU * 5 + 999999UL) / 1000000UL))
static __attribute__((noinline)) void twi_half_clock(void)
{
	__builtin_avr_delay_cycles(TWI_HALF_CLOCK_CYCLES - 7);
}

bool twi_clear_bus(void)
{
	const mcu_port_t port = mcu_port_at(BOARD_TWI_PORT - 'A');
	const mcu_port_t *p = &port;
	const uint8_t scl = _BV(BOARD_TWI_SCL);
	const uint8_t sda = _BV(BOARD_TWI_SDA);

	twi_fence_wait();  /* a STOP would end an abandoned frame as complete */
	twi.open = 0;
	TWCR = 0;  /* the pins become ordinary port pins */
	line_release(p, scl);
	line_release(p, sda);
	twi_half_clock();
	for (uint8_t i = 0; i < 9 && !(*p->pin & sda); i++) {
		line_low(p, scl);
		twi_half_clock();
		line_release(p, scl);
		twi_half_clock();
	}
	/* SDA still low after nine clocks: no STOP can be made. */
	bool free = false;
	if (*p->pin & sda) {
		/* STOP: SDA rises while SCL is high. */
		line_low(p, scl);
		line_low(p, sda);
		twi_half_clock();
		line_release(p, scl);
		twi_half_clock();
		line_release(p, sda);
		twi_half_clock();
		/* SDA was free; is SCL? */
		free = *p->pin & scl;
	}
	/* Back to the TWI, pins as after reset; TWBR/TWPS were kept. */
	*p->port &= (uint8_t)~(scl | sda);
	TWCR = _BV(TWEN);
	return free;
}
