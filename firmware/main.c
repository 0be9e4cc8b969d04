/* ORFA firmware: drivers behind a register map, one front end before it. */
#include <avr/interrupt.h>
#include <avr/wdt.h>

#include "firmware/clock.h"
#include "firmware/front.h"
#include "firmware/mcu.h"
#include "firmware/pins.h"
#include "firmware/regmap.h"
#include "firmware/sys.h"

int main(void)
{
	sys_boot(mcu_watchdog_start());
	mcu_jtag_off();
	clock_init();
	pins_init();
	regmap_init();
	front_init();
	sei();
	/* The only place that feeds the watchdog (besides waits that feed
	 * on progress: uart_putc, the TWI master): a stuck main loop or a
	 * stuck interrupt both end in a reset. The front end watches the
	 * link-loss failsafe when it is idle (sys_poll()). */
	for (;;) {
		wdt_reset();
		front_poll();
		regmap_later();
	}
}
