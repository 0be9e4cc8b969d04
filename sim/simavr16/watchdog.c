/*
 * watchdog.c: repairs of simavr 1.6's watchdog (watchdog.h).
 */
#include <string.h>

#include "sim_regbit.h"

#include "periph/io_hook.h"
#include "simavr16/watchdog.h"

/* simavr 1.6 keeps a running watchdog's period when the firmware changes
 * the prescaler (it compares the new WDP bits with themselves), and it
 * restarts the watchdog at 16 ms after a watchdog reset: the firmware's
 * 250 ms never took after the first watchdog reset. Chained after
 * simavr's WDTCR handler: the period follows WDP, from the next WDR on
 * (every WDR restarts the timer with this period). */
static void s16_wdtcr_write(avr_t *avr, avr_io_addr_t addr, uint8_t v, void *param)
{
	simavr16_watchdog_t *w = param;
	uint8_t wdp;

	io_hook_pass_write(avr, &w->prev, addr, v);
	wdp = avr_regbit_get_array(avr, w->wd->wdp, 4);
	w->wd->cycle_count = ((avr_cycle_count_t)2048 << wdp) * avr->frequency / 128000;
}

/* The firmware's main loops execute WDR all the time, and simavr turns
 * every WDR into avr_ioctl(AVR_IOCTL_WATCHDOG_RESET), which asks each IO
 * module in list order until one answers: 11-18% of a board's time went
 * there (perf). With the watchdog first the walk ends at once. Only the
 * order of the modules' reset hooks changes, and the watchdog's touches
 * nothing another module owns. */
static void s16_watchdog_first(avr_t *avr)
{
	avr_io_t **link = &avr->io_port;

	while (*link && strcmp((*link)->kind, "watchdog") != 0) {
		link = &(*link)->next;
	}
	if (*link && *link != avr->io_port) {
		avr_io_t *wd = *link;

		*link = wd->next;
		wd->next = avr->io_port;
		avr->io_port = wd;
	}
}

void simavr16_watchdog_init(simavr16_watchdog_t *w, avr_t *avr)
{
	memset(w, 0, sizeof(*w));
	s16_watchdog_first(avr);
	for (avr_io_t *io = avr->io_port; io; io = io->next) {
		if (io->kind && !strcmp(io->kind, "watchdog")) {
			w->wd = (avr_watchdog_t *)io;
		}
	}
	if (!w->wd || !w->wd->wdce.reg) {
		return;
	}
	io_hook_chain(avr, w->wd->wdce.reg, NULL, s16_wdtcr_write, w, &w->prev);
}
