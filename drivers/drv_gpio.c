#include "drivers/drv_gpio.h"

#include "firmware/pins.h"
#include "firmware/port_io.h"

/* The driver's ports in register order, as port indices (0 = A). */
static const ORFA_FLASH uint8_t gpio_ports[GPIO_NPORTS] = {
#define X(letter) (uint8_t)((letter) - 'A'),
	BOARD_GPIO_PORTS(X)
#undef X
};

/* What a write's bytes so far rule out (regmap.h): refused at once. */
reg_status_t drv_gpio_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)reg;
	(void)data;
	return len > 2 ? REG_BAD_LENGTH : REG_OK;  /* value, mask */
}

/* Write [value] or [value][mask]: only lines in the mask that GPIO holds
 * change; lines of other functions are left alone (not an error). */
reg_status_t drv_gpio_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	if (len < 1 || len > 2) {
		return REG_BAD_LENGTH;
	}
	uint8_t is_mode = reg >= GPIO_NPORTS;
	uint8_t port = gpio_ports[is_mode ? reg - GPIO_NPORTS : reg];
	uint8_t mask = (len == 2 ? data[1] : 0xFF) & pins_gpio_mask(port);
	if (is_mode) {
		port_io_dir(port, mask, data[0]);
	} else {
		port_io_write(port, mask, data[0]);
	}
	return REG_OK;
}

/* Values read the levels on the pins; modes read the direction bits. */
uint8_t drv_gpio_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	(void)max;
	uint8_t is_mode = reg >= GPIO_NPORTS;
	uint8_t port = gpio_ports[is_mode ? reg - GPIO_NPORTS : reg];
	dst[0] = is_mode ? port_io_dirs(port) : port_io_pins(port);
	return 1;
}

void drv_gpio_init(void)
{
}
