#include "fakes.h"

#include <stdio.h>
#include <string.h>

#include "firmware/twi_master.h"
#include "firmware/twi_rate.h"
#include "serialgate/sg_exec.h"

char bus_log[4096];
uint8_t eeprom[256];
char out_buf[65536];
unsigned out_len;

static struct {
	int device;      /* addressed device, -1 none */
	int first_write; /* next written byte is the EEPROM word address */
	uint8_t ptr;
} bus;

static void logf_(const char *fmt, unsigned v)
{
	size_t n = strlen(bus_log);
	snprintf(bus_log + n, sizeof bus_log - n, fmt, v);
}

void fakes_reset(void)
{
	bus_log[0] = 0;
	out_len = 0;
	out_buf[0] = 0;
	memset(eeprom, 0xFF, sizeof eeprom);
	bus.device = -1;
}

void sg_out(uint8_t c)
{
	if (out_len + 1 < sizeof out_buf) {
		out_buf[out_len++] = (char)c;
		out_buf[out_len] = 0;
	}
}

void sg_out2(uint8_t a, uint8_t b)
{
	sg_out(a);
	sg_out(b);
}

void sg_lost_answered(void)
{
}

/* Devices: 0xA0 EEPROM; 0x50 acknowledges its address, refuses data;
 * 0x60 hangs the bus (every step fails); 0x62 takes everything, then holds
 * SCL so that no STOP can be made (the transaction is abandoned). */
twi_result_t twi_start(uint8_t addr8)
{
	logf_("S %02X", addr8);
	uint8_t dev = addr8 & 0xFE;
	if (dev == 0x60) {
		logf_("! ", 0);
		return TWI_FAIL;
	}
	if (dev == 0x62) {
		logf_("+ ", 0);
		bus.device = dev;
		return TWI_ACK;
	}
	if (dev != 0xA0 && dev != 0x50) {
		logf_("- ", 0);
		bus.device = -1;
		return TWI_NACK;
	}
	logf_("+ ", 0);
	bus.device = dev;
	bus.first_write = !(addr8 & 1);
	return TWI_ACK;
}

static twi_result_t twi_write(uint8_t byte)
{
	logf_("W%02X", byte);
	if (bus.device == 0x62) {
		logf_("+ ", 0);
		return TWI_ACK;
	}
	if (bus.device != 0xA0) {
		logf_("- ", 0);
		return TWI_NACK;
	}
	logf_("+ ", 0);
	if (bus.first_write) {
		bus.ptr = byte;
		bus.first_write = 0;
	} else {
		eeprom[bus.ptr] = byte;
		bus.ptr = (uint8_t)((bus.ptr & 0xF8) | ((bus.ptr + 1) & 7));
	}
	return TWI_ACK;
}

static twi_result_t twi_read(uint8_t *byte, bool ack)
{
	*byte = bus.device == 0xA0 ? eeprom[bus.ptr++] : 0xFF;
	logf_("R%02X", *byte);
	logf_(ack ? "+ " : "- ", 0);
	return TWI_ACK;
}

twi_result_t twi_write_bytes(const uint8_t *data, uint8_t n)
{
	for (uint8_t i = 0; i < n; i++) {
		twi_result_t r = twi_write(data[i]);
		if (r != TWI_ACK) {
			return r;
		}
	}
	return TWI_ACK;
}

twi_result_t twi_read_bytes(uint8_t *data, uint8_t n)
{
	for (uint8_t i = 0; i < n; i++) {
		twi_result_t r = twi_read(&data[i], (uint8_t)(i + 1) < n);
		if (r != TWI_ACK) {
			return r;
		}
	}
	return TWI_ACK;
}

bool twi_stop(void)
{
	bool held = bus.device == 0x62;
	logf_(held ? "P! " : "P ", 0);
	bus.device = -1;
	return !held;
}

void twi_idle(void)
{
}

bool twi_clear_bus(void)
{
	logf_("X ", 0);
	return true;
}

uint16_t twi_set_khz(uint16_t khz)
{
	return twi_rate_for_khz(F_CPU, khz).khz;
}

/* --- the test driver ---------------------------------------------------- */

static struct {
	uint8_t data[4];
	uint8_t len;
} fake;

unsigned fake_safe_calls;
volatile uint16_t clock_wraps;

void drv_fake_safe(void)
{
	fake_safe_calls++;
}

void drv_fake_init(void)
{
	fake.len = 1;
	fake.data[0] = 0x5A;
}

reg_status_t drv_fake_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)data;
	if (reg == 1) {
		return REG_NOT_WRITABLE;
	}
	return reg == 0 && len > 4 ? REG_BAD_LENGTH : REG_OK;
}

reg_status_t drv_fake_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	if (reg == 1) {
		return REG_NOT_WRITABLE;
	}
	if (reg == 2) {
		return REG_OK;
	}
	if (len == 0 || len > 4) {
		return REG_BAD_LENGTH;
	}
	memcpy(fake.data, data, len);
	fake.len = len;
	return REG_OK;
}

uint8_t drv_fake_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	static const uint8_t ro[3] = { 0x11, 0x22, 0x33 };
	const uint8_t *src = reg == 0 ? fake.data : ro;
	uint8_t n = reg == 0 ? fake.len : 3;
	if (reg == 2) {
		return 0;
	}
	if (n > max) {
		n = max;
	}
	memcpy(dst, src, n);
	return n;
}

