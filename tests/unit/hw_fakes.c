#include "hw_fakes.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "drivers/adc_hw.h"
#include "drivers/motor_hw.h"
#include "drivers/servo_hw.h"
#include "drivers/spi_hw.h"
#include "firmware/board_pins.h"
#include "firmware/pins.h"
#include "firmware/port_io.h"

uint8_t port_out[BOARD_NPORTS];
uint8_t port_ddr[BOARD_NPORTS];
uint8_t port_ext[BOARD_NPORTS];
char hw_log[8192];
hw_rec_t hw;
uint16_t adc_in[8];

/* firmware/clock.h: the drivers' tests never let time pass (weak: the
 * gateway fuzz harness links fakes.c, whose tests set the clock, too). */
__attribute__((weak)) volatile uint16_t clock_wraps;

static uint8_t miso[256];
static unsigned miso_len, miso_pos;

static void logf_(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

static void logf_(const char *fmt, ...)
{
	size_t n = strlen(hw_log);
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(hw_log + n, sizeof hw_log - n, fmt, ap);
	va_end(ap);
}

void hw_log_clear(void)
{
	hw_log[0] = 0;
}

void hw_fakes_reset(void)
{
	memset(port_out, 0, sizeof port_out);
	memset(port_ddr, 0, sizeof port_ddr);
	memset(port_ext, 0, sizeof port_ext);
	memset(&hw, 0, sizeof hw);
	memset(adc_in, 0, sizeof adc_in);
	miso_len = miso_pos = 0;
	hw_log_clear();
}

/* --- port_io ------------------------------------------------------------ */

void port_io_write(uint8_t port, uint8_t mask, uint8_t value)
{
	port_out[port] = (uint8_t)((port_out[port] & ~mask) | (value & mask));
	logf_("W%c%02X:%02X ", 'A' + port, mask, value & mask);
}

void port_io_dir(uint8_t port, uint8_t mask, uint8_t value)
{
	port_ddr[port] = (uint8_t)((port_ddr[port] & ~mask) | (value & mask));
	logf_("D%c%02X:%02X ", 'A' + port, mask, value & mask);
}

uint8_t port_io_pins(uint8_t port)
{
	return (uint8_t)((port_out[port] & port_ddr[port]) | (port_ext[port] & ~port_ddr[port]));
}

uint8_t port_io_out(uint8_t port)
{
	return port_out[port];
}

uint8_t port_io_dirs(uint8_t port)
{
	return port_ddr[port];
}

/* --- servo_hw: claims like the board's backend ---------------------------- */

void servo_hw_init(void)
{
	hw.servo_inits++;
	/* servo_4017.c: the counter clocks and reset are the servos' for good
	 * (clocks low, reset high). servo_pins.c claims nothing here. */
	for (uint8_t c = 0; board_pin(BF_SERVO_CLK, c) != BOARD_PIN_NONE; c++) {
		uint8_t pin = board_pin(BF_SERVO_CLK, c);
		pins_claim(pin, PIN_SERVO_CLK);
		port_io_write(PIN_PORT(pin), PIN_MASK(pin), 0);
		port_io_dir(PIN_PORT(pin), PIN_MASK(pin), PIN_MASK(pin));
	}
	uint8_t rst = board_pin(BF_SERVO_RST, 0);
	if (rst != BOARD_PIN_NONE) {
		pins_claim(rst, PIN_SERVO_CLK);
		port_io_write(PIN_PORT(rst), PIN_MASK(rst), PIN_MASK(rst));
		port_io_dir(PIN_PORT(rst), PIN_MASK(rst), PIN_MASK(rst));
	}
}

bool servo_hw_can_claim(uint8_t ch)
{
	uint8_t pin = board_pin(BF_SERVO, ch);
	return pin == BOARD_PIN_NONE || pins_can_claim(pin, PIN_SERVO);
}

/* servo_pins.c (a pin per channel): take the pin, output low. servo_4017.c
 * (no pin per channel): nothing to take. */
bool servo_hw_claim(uint8_t ch)
{
	uint8_t pin = board_pin(BF_SERVO, ch);
	if (pin != BOARD_PIN_NONE) {
		if (!pins_claim(pin, PIN_SERVO)) {
			return false;
		}
		port_io_write(PIN_PORT(pin), PIN_MASK(pin), 0);
		port_io_dir(PIN_PORT(pin), PIN_MASK(pin), PIN_MASK(pin));
	}
	hw.servo_claimed[ch] = 1;
	hw.servo_claims++;
	return true;
}

void servo_hw_release(uint8_t ch)
{
	uint8_t pin = board_pin(BF_SERVO, ch);
	if (pin != BOARD_PIN_NONE) {
		pins_release(pin, PIN_SERVO);
	}
	hw.servo_claimed[ch] = 0;
	hw.servo_releases++;
}

void servo_hw_apply(const uint16_t *widths_us)
{
	memcpy(hw.servo_width, widths_us, sizeof hw.servo_width);
	hw.servo_applies++;
}

void servo_hw_later(const uint16_t *widths_us)
{
	(void)widths_us;
}

/* --- motor_hw ------------------------------------------------------------- */

void motor_hw_init(void)
{
	hw.motor_inits++;
}

void motor_hw_apply(const uint8_t *pwm, const uint8_t *dir, uint8_t lines)
{
	memcpy(hw.motor_pwm, pwm, sizeof hw.motor_pwm);
	memcpy(hw.motor_dir, dir, sizeof hw.motor_dir);
	hw.motor_lines = lines;
	hw.motor_applies++;
}

/* --- adc_hw --------------------------------------------------------------- */

void adc_hw_config(uint8_t refs, uint8_t mask)
{
	hw.adc_configs++;
	hw.adc_refs = refs;
	hw.adc_mask = mask;
}

uint16_t adc_hw_value(uint8_t ch)
{
	return (hw.adc_mask & (1u << ch)) ? (uint16_t)(adc_in[ch] & 0x3FF) : 0;
}

/* --- spi_hw --------------------------------------------------------------- */

void spi_script(const uint8_t *bytes, unsigned n)
{
	memcpy(miso, bytes, n);
	miso_len = n;
	miso_pos = 0;
}

void spi_hw_init(void)
{
	hw.spi_inits++;
}

void spi_hw_config(uint8_t divider, uint8_t mode, uint8_t lsb_first)
{
	hw.spi_configs++;
	hw.spi_div = divider;
	hw.spi_mode = mode;
	hw.spi_lsb = lsb_first != 0;
}

void spi_hw_exchange(uint8_t *buf, uint8_t n)
{
	logf_("X");
	for (uint8_t i = 0; i < n; i++) {
		logf_("%02X", buf[i]);
	}
	logf_(">");
	for (uint8_t i = 0; i < n; i++) {
		buf[i] = miso_pos < miso_len ? miso[miso_pos++] : 0xFF;
		logf_("%02X", buf[i]);
	}
	logf_(" ");
	hw.spi_bytes += n;
}
