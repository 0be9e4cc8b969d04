/*
 * avr_step.c: avr_callback_run_raw() of simavr 1.6 (sim_avr.c) in a loop,
 * with avr_cycle_timer_process() called only when a timer is due. Skipping
 * it otherwise changes nothing: with no timer due it only returns the
 * cycles to the next one and sets avr->run_cycle_count, which stays 1
 * (run_cycle_limit is 1: avr_run_one runs one instruction per call).
 */
#include "harness/avr_step.h"

#include "harness/profile.h"

#include "sim_core.h"
#include "sim_interrupts.h"
#include "simavr16/interrupt.h"

static inline int avr_step_timer_due(const avr_t *avr)
{
	const avr_cycle_timer_slot_t *t = avr->cycle_timers.timer;

	return t && t->when <= avr->cycle;
}

/* The rare part of avr_step_after(): a timer due, or sleep. */
static void avr_step_slow(avr_t *avr, avr_flashaddr_t new_pc)
{
	avr_cycle_count_t sleep = avr_cycle_timer_process(avr);

	avr->pc = new_pc;
	if (avr->state == cpu_Sleeping) {
		if (!avr->sreg[S_I]) {
			if (avr->log) {
				AVR_LOG(avr, LOG_TRACE, "simavr: sleeping with interrupts off,"
					" quitting gracefully\n");
			}
			avr->state = cpu_Done;
			return;
		}
		avr->sleep(avr, sleep);
		avr->cycle += 1 + sleep;
	}
	if ((avr->state == cpu_Running || avr->state == cpu_Sleeping) && avr->interrupt_state) {
		simavr16_interrupt_latency(avr);
		avr_service_interrupts(avr);
	}
}

static inline void avr_step_after_inline(avr_t *avr, avr_flashaddr_t new_pc)
{
	if (__builtin_expect(avr->state == cpu_Sleeping || avr_step_timer_due(avr), 0)) {
		avr_step_slow(avr, new_pc);
		return;
	}
	avr->pc = new_pc;
	if (avr->interrupt_state && avr->state == cpu_Running) {
		simavr16_interrupt_latency(avr);
		avr_service_interrupts(avr);
	}
}

void avr_step_after(avr_t *avr, avr_flashaddr_t new_pc)
{
	avr_step_after_inline(avr, new_pc);
}

int avr_step_until(avr_t *avr, uint64_t end)
{
	if (avr->run != avr_callback_run_raw) {
		while (avr->cycle < end) {	/* a gdb or another run loop: simavr's own */
			avr_run(avr);
			if (avr->state == cpu_Done || avr->state == cpu_Crashed) {
				break;
			}
		}
		return avr->state;
	}
	while (avr->cycle < end) {
		avr_flashaddr_t new_pc = avr->pc;

		profile_note(avr);
		if (avr->state == cpu_Running) {
			new_pc = avr_run_one(avr);
		}
		avr_step_after_inline(avr, new_pc);
		if (avr->state == cpu_Done || avr->state == cpu_Crashed) {
			break;
		}
	}
	return avr->state;
}
