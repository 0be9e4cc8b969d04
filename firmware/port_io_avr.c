#include "firmware/port_io.h"

#include <util/atomic.h>

#include "firmware/mcu.h"

void port_io_write(uint8_t port, uint8_t mask, uint8_t value)
{
	mcu_port_t p = mcu_port(port);
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		*p.port = (uint8_t)((*p.port & ~mask) | (value & mask));
	}
}

void port_io_dir(uint8_t port, uint8_t mask, uint8_t value)
{
	mcu_port_t p = mcu_port(port);
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		*p.ddr = (uint8_t)((*p.ddr & ~mask) | (value & mask));
	}
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
