#include "drivers/drv_servo.h"

#include <stdbool.h>
#include <string.h>

#include "drivers/servo_hw.h"

#define SERVO_REG_RS 0
#define SERVO_REG_SP 1

static struct {
	uint16_t width[SERVO_CHANNELS];  /* us; 0 = off */
	uint8_t first;                   /* first channel a read of SP gives */
} servo;

void drv_servo_init(void)
{
	/* every width off, reads from channel 0: the struct zeroed byte by
	 * byte (one loop; power-on, as .bss is, for the host's tests too) */
	uint8_t *b = (uint8_t *)&servo;
	for (uint8_t i = 0; i < sizeof servo; i++) {
		b[i] = 0;
	}
	servo_hw_init();
}

static uint16_t servo_clamp(uint16_t us)
{
	if (us == 0) {
		return 0;
	}
	if (us < SERVO_MIN_US) {
		return SERVO_MIN_US;
	}
	return us > SERVO_MAX_US ? SERVO_MAX_US : us;
}

/* Whether `at` is a multiple of 3, as a multiply: at * 171 (3's inverse
 * modulo 256) is at most 85 for exactly those bytes (3k gives k). No
 * division in a TWI interrupt (drv_servo_check()), none linked at all (a
 * write's length); one multiply and a compare, not at / 3 times 3. */
static bool servo_triple_at(uint8_t at)
{
	return (uint8_t)(at * 171u) <= 85;
}

/* SP: [channel] selects the first channel for reads; [channel][hi][lo]...
 * (up to 16) sets widths. The whole write applies or none of it. */
static reg_status_t servo_write_sp(const uint8_t *data, uint8_t len)
{
	if (len == 1) {
		if (data[0] >= SERVO_CHANNELS) {
			return REG_BAD_VALUE;
		}
		servo.first = data[0];
		return REG_OK;
	}
	if (len > 3 * SERVO_MAX_TRIPLES || !servo_triple_at(len)) {
		return REG_BAD_LENGTH;
	}
	uint16_t next[SERVO_CHANNELS];
	memcpy(next, servo.width, sizeof next);
	bool onoff = false;  /* a triple turns its channel on or off */
	for (uint8_t i = 0; i < len; i += 3) {
		uint8_t ch = data[i];
		if (ch >= SERVO_CHANNELS) {
			return REG_BAD_VALUE;  /* nothing applied yet: next is a copy */
		}
		uint16_t us = servo_clamp((uint16_t)(data[i + 1] << 8 | data[i + 2]));
		next[ch] = us;
		if (!us != !servo.width[ch]) {
			onoff = true;
		}
	}
	/* Only the channels written can change: the loops below go over the
	 * triples (a channel written twice is looked at twice, to the same
	 * effect). Channels turned on take their pins. All are checked before
	 * any is taken: a claim sets its pin up (output low) and a release
	 * cannot bring back what GPIO had there. Most writes only change
	 * widths: the claims and releases are looked for only where some
	 * channel starts or stops. */
	bool starts = false, stops = false;
	for (uint8_t i = 0; onoff && i < len; i += 3) {
		uint8_t ch = data[i];
		if (next[ch] != servo.width[ch]) {
			if (!servo.width[ch]) {
				starts = true;
				if (!servo_hw_can_claim(ch)) {
					return REG_PIN_BUSY;
				}
			} else if (!next[ch]) {
				stops = true;
			}
		}
	}
	for (uint8_t i = 0; starts && i < len; i += 3) {
		uint8_t ch = data[i];
		if (next[ch] && !servo.width[ch]) {
			servo_hw_claim(ch);
		}
	}
	servo_hw_apply(next);
	for (uint8_t i = 0; stops && i < len; i += 3) {
		uint8_t ch = data[i];
		if (!next[ch] && servo.width[ch]) {
			servo_hw_release(ch);
		}
	}
	memcpy(servo.width, next, sizeof next);
	return REG_OK;
}

void drv_servo_later(void)
{
	servo_hw_later(servo.width);
}

reg_status_t drv_servo_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	if (reg == SERVO_REG_RS) {
		return REG_OK;
	}
	if (len > 3 * SERVO_MAX_TRIPLES) {
		return REG_BAD_LENGTH;
	}
	/* Every third byte names a channel (a 1-byte write too): bytes 0, 3,
	 * 6, ... */
	uint8_t at = (uint8_t)(len - 1);
	if (data[at] >= SERVO_CHANNELS && servo_triple_at(at)) {
		return REG_BAD_VALUE;
	}
	return REG_OK;
}

reg_status_t drv_servo_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	if (reg == SERVO_REG_RS) {
		return REG_OK;  /* driver 1.0's channel mask: accepted, not needed */
	}
	return servo_write_sp(data, len);
}

/* RS: the mask of pulsing channels, channel 0 in the last byte's bit 0.
 * SP: the widths from the first channel on, 2 bytes each. */
uint8_t drv_servo_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	uint8_t n = 0;
	if (reg == SERVO_REG_RS) {
		/* from the last channel down, each shifted in at bit 0: a byte
		 * is done at a channel that is a multiple of 8 */
		_Static_assert(SERVO_CHANNELS % 8 == 0, "whole bytes of the mask");
		uint8_t bits = 0;
		for (uint8_t ch = SERVO_CHANNELS; ch-- && n < max;) {
			bits = (uint8_t)(bits << 1);
			if (servo.width[ch]) {
				bits |= 1;
			}
			if (!(ch & 7)) {
				dst[n++] = bits;
			}
		}
		return n;
	}
	for (uint8_t ch = servo.first; ch < SERVO_CHANNELS && n < max; ch++) {
		dst[n++] = (uint8_t)(servo.width[ch] >> 8);
		if (n == max) {
			break;
		}
		dst[n++] = (uint8_t)servo.width[ch];
	}
	return n;
}

void drv_servo_safe(void)
{
	/*
	 * Each pulsing channel is turned off by the write a host would send,
	 * [ch][00][00] to SP, so the failsafe does exactly what those writes
	 * do; a width of 0 is always accepted. One channel at a time, so no
	 * buffer of 16 triples sits on the main loop's stack. Going through
	 * drv_servo_write() leaves servo_write_sp() and servo_hw_apply() with
	 * one caller each, which the compiler inlines them into.
	 */
	for (uint8_t ch = 0; ch < SERVO_CHANNELS; ch++) {
		if (servo.width[ch]) {
			const uint8_t off[3] = { ch, 0, 0 };
			(void)drv_servo_write(SERVO_REG_SP, off, sizeof off);
		}
	}
}
