#include "firmware/mcu.h"

#include <avr/wdt.h>

/* PINx, DDRx, PORTx data addresses in letter order from 'A'. Named, not
 * computed: the ATmega128's port F registers are not next to each other.
 * Addresses rather than pointers in flash: avr-gcc 5.4 at -O2 miscompiled
 * reads of pointers through __flash. */
static const __flash uint8_t port_regs[][3] = {
#define MCU_PORT_ROW(letter) \
	{ _SFR_MEM_ADDR(PIN##letter), _SFR_MEM_ADDR(DDR##letter), _SFR_MEM_ADDR(PORT##letter) },
	MCU_PORT_LETTERS(MCU_PORT_ROW)
#undef MCU_PORT_ROW
};

mcu_port_t mcu_port(uint8_t index)
{
	mcu_port_t p = {
		.pin = (volatile uint8_t *)(uint16_t)port_regs[index][0],
		.ddr = (volatile uint8_t *)(uint16_t)port_regs[index][1],
		.port = (volatile uint8_t *)(uint16_t)port_regs[index][2],
	};
	return p;
}

uint8_t mcu_watchdog_start(void)
{
	uint8_t flags = MCU_RESET_FLAGS;
	MCU_RESET_FLAGS = 0;
	wdt_enable(WDTO_250MS);
	return flags;
}

void mcu_jtag_off(void)
{
	/* JTD must be written twice within four cycles. */
	uint8_t v = MCUCSR | _BV(JTD);
	MCUCSR = v;
	MCUCSR = v;
}
