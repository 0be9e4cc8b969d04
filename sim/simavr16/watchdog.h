/*
 * watchdog.h: repairs of simavr 1.6's watchdog, to delete with the upgrade
 * to a simavr that has them right:
 *
 *  - the period follows WDP from the next WDR on (simavr 1.6 keeps a
 *    running watchdog's period and restarts it at 16 ms after a watchdog
 *    reset);
 *  - the watchdog first in simavr's module list, so the WDR ioctl ends its
 *    walk at once (11-18% of a board's time otherwise).
 */
#ifndef SIM_SIMAVR16_WATCHDOG_H
#define SIM_SIMAVR16_WATCHDOG_H

#include "sim_avr.h"
#include "avr_watchdog.h"

#include "periph/io_hook.h"

typedef struct simavr16_watchdog_t {
	avr_watchdog_t *wd;		/* simavr's watchdog (NULL: none) */
	io_hook_prev_t prev;		/* simavr's WDTCR write handler */
} simavr16_watchdog_t;

/* Apply the repairs to AVR (after avr_init and the other modules). */
void simavr16_watchdog_init(simavr16_watchdog_t *w, avr_t *avr);

#endif
