#include "firmware/mcu.h"

#include <avr/wdt.h>

/* Ports in letter order from 'A'; each MCU lists the ports it has. */
static const __flash mcu_port_t ports[] = {
	{ &PINA, &DDRA, &PORTA },
	{ &PINB, &DDRB, &PORTB },
	{ &PINC, &DDRC, &PORTC },
	{ &PIND, &DDRD, &PORTD },
#if defined(__AVR_ATmega128__)
	{ &PINE, &DDRE, &PORTE },
	{ &PINF, &DDRF, &PORTF },
	{ &PING, &DDRG, &PORTG },
#endif
};

const __flash mcu_port_t *mcu_port(char letter)
{
	uint8_t i = (uint8_t)(letter - 'A');
	if (i >= sizeof ports / sizeof ports[0]) {
		return 0;
	}
	return &ports[i];
}

void mcu_watchdog_start(void)
{
	MCU_RESET_FLAGS = 0;
	wdt_enable(WDTO_250MS);
}

void mcu_jtag_off(void)
{
	/* JTD must be written twice within four cycles. */
	uint8_t v = MCUCSR | _BV(JTD);
	MCUCSR = v;
	MCUCSR = v;
}
