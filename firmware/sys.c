#include "firmware/sys.h"

#include "firmware/clock.h"
#include "firmware/flash.h"

_Static_assert((uint32_t)SYS_FAILSAFE_MAX_MS * CLOCK_HZ / 1000u + 1u < 65536u,
	       "the longest FAILSAFE fits the 16-bit clock");

#define SYS_REG_RESET    0
#define SYS_REG_FAILSAFE 1

/* The causes survive resets that keep SRAM (watchdog, external, brown-out)
 * until the host clears them; `check` (the complement) tells them from
 * what SRAM holds after power-up. sys_keep() out of line: sys_boot() and
 * a RESET write each had it inlined (4 bytes). */
static struct {
	uint8_t causes;
	uint8_t check;
} sys_kept ORFA_NOINIT;

volatile uint8_t sys_heard;

static struct {
	uint16_t ms;       /* FAILSAFE as written; 0 = off */
	uint16_t ticks;    /* the same in clock ticks */
	uint16_t last;     /* the clock when a request was last heard */
	uint8_t tripped;   /* the safe state is applied for this quiet spell */
} sys;

static __attribute__((noinline)) void sys_keep(uint8_t causes)
{
	sys_kept.causes = causes;
	sys_kept.check = (uint8_t)~causes;
}

void sys_boot(uint8_t reset_flags)
{
	uint8_t causes = 0;
	if (!(reset_flags & SYS_RESET_POWER) && (uint8_t)(sys_kept.check ^ sys_kept.causes) == 0xFF) {
		causes = sys_kept.causes;
	}
	sys_keep((uint8_t)(causes | (reset_flags & SYS_RESET_ALL)));
}

void drv_sys_init(void)
{
	sys.ms = 0;
	sys.ticks = 0;
	sys.tripped = 0;
}

/* RESET takes 1 byte, FAILSAFE 2. */
#define SYS_REG_LEN(reg) ((uint8_t)((reg) + 1))

/* Only a length can be refused byte by byte: a FAILSAFE above the longest
 * is decided when the frame ends, as a motor's direction is. */
reg_status_t drv_sys_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)data;
	return len > SYS_REG_LEN(reg) ? REG_BAD_LENGTH : REG_OK;
}

/* ceil(ms * CLOCK_HZ / 1000) in 16 bits (no 32-bit division linked): the
 * ticks a millisecond, TICKS_NUM / TICKS_DEN, as a whole part and a
 * remainder, whose product with the longest FAILSAFE fits. */
#define SYS_TICKS_NUM ((uint16_t)(CLOCK_HZ / 200u))
#define SYS_TICKS_DEN 5u
_Static_assert(CLOCK_HZ % 200u == 0, "ticks a millisecond: CLOCK_HZ / 200 fifths");
_Static_assert((uint32_t)SYS_FAILSAFE_MAX_MS * (SYS_TICKS_NUM % SYS_TICKS_DEN) + SYS_TICKS_DEN
	       <= 0xFFFFu, "the remainder's product fits 16 bits");
static uint16_t sys_ticks_up(uint16_t ms)
{
	uint16_t whole = (uint16_t)(SYS_TICKS_NUM / SYS_TICKS_DEN);
	uint16_t part = (uint16_t)(SYS_TICKS_NUM % SYS_TICKS_DEN);
	return (uint16_t)(ms * whole + (uint16_t)(ms * part + SYS_TICKS_DEN - 1u) / SYS_TICKS_DEN);
}

reg_status_t drv_sys_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	if (len != SYS_REG_LEN(reg)) {
		return REG_BAD_LENGTH;
	}
	if (reg == SYS_REG_RESET) {
		sys_keep((uint8_t)(sys_kept.causes & ~data[0]));
		return REG_OK;
	}
	uint16_t ms = (uint16_t)(data[0] << 8 | data[1]);
	if (ms > SYS_FAILSAFE_MAX_MS) {
		return REG_BAD_VALUE;
	}
	sys.ms = ms;
	/* Rounded up, and one tick more: the clock is read in whole ticks, so
	 * the request may have come up to a tick after the one counted from.
	 * Never early, at most two ticks (0.56 ms) late. */
	sys.ticks = ms ? (uint16_t)(sys_ticks_up(ms) + 1u) : 0;
	sys.last = clock_now();
	sys.tripped = 0;
	sys_heard = 0;
	return REG_OK;
}

uint8_t drv_sys_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	if (reg == SYS_REG_RESET) {
		dst[0] = sys_kept.causes;
		return 1;
	}
	dst[0] = (uint8_t)(sys.ms >> 8);
	if (max < 2) {
		return 1;
	}
	dst[1] = (uint8_t)sys.ms;
	return 2;
}

void sys_poll(void)
{
	if (!sys.ticks) {
		return;  /* off */
	}
	if (sys_heard) {
		sys_heard = 0;
		sys.last = clock_now();
		sys.tripped = 0;
		return;
	}
	if (!sys.tripped && (uint16_t)(clock_now() - sys.last) >= sys.ticks) {
		sys.tripped = 1;
		regmap_safe();
	}
}
