/* ORFA firmware: drivers behind a register map, one front end before it. */
#include <avr/interrupt.h>
#include <avr/wdt.h>

#include "firmware/clock.h"
#include "firmware/front.h"
#include "firmware/mcu.h"
#include "firmware/pins.h"
#include "firmware/regmap.h"

int main(void)
{
	mcu_watchdog_start();
	mcu_jtag_off();
	clock_init();
	pins_init();
	regmap_init();
	front_init();
	sei();
	for (;;) {
		wdt_reset();
		front_poll();
	}
}
