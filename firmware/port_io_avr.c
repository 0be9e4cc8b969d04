#include "firmware/port_io.h"

#include <util/atomic.h>

#include "firmware/mcu.h"

/* The bits of `mask` in register r set to value's: one body for a port's
 * output and direction registers. */
static __attribute__((noinline)) void port_io_set(volatile uint8_t *r, uint8_t mask, uint8_t value)
{
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		*r = (uint8_t)((*r & ~mask) | (value & mask));
	}
}

void port_io_write(uint8_t port, uint8_t mask, uint8_t value)
{
	port_io_set(mcu_port(port).port, mask, value);
}

void port_io_dir(uint8_t port, uint8_t mask, uint8_t value)
{
	port_io_set(mcu_port(port).ddr, mask, value);
}

uint8_t port_io_pins(uint8_t port)
{
	return *mcu_port(port).pin;
}

uint8_t port_io_out(uint8_t port)
{
	return *mcu_port(port).port;
}

uint8_t port_io_dirs(uint8_t port)
{
	return *mcu_port(port).ddr;
}
