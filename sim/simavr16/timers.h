/*
 * timers.h: repairs of simavr 1.6 that the board model needs, kept apart
 * so they can be deleted when simavr is upgraded (docs/simulator.md, "What
 * simavr 1.6 gets wrong"):
 *
 *  - a compare output change stamped with the cycle the compare happened
 *    at, and the fast-PWM "before the match" levels simavr gives in normal
 *    and CTC modes dropped (simavr16_event_cycle, simavr16_oc_event_real);
 *  - an OCRnx written in fast PWM applied at the end of the period, and
 *    mode 14's OCR double buffer and lost short pulses (the OCR hooks and
 *    the PWM overflow watch);
 *  - TIFR/ETIFR writes clearing only the flags written 1;
 *  - the force-output-compare strobes (FOCnx), which simavr lacks;
 *  - level-triggered INTn not polled on every cycle.
 */
#ifndef SIM_SIMAVR16_TIMERS_H
#define SIM_SIMAVR16_TIMERS_H

#include <stdint.h>

#include "sim_avr.h"
#include "avr_timer.h"

#include "periph/io_hook.h"
#include "periph/sim_mcu.h"

struct board_model_t;
struct bm_oc_t;

#define S16_MAX_OCR 12
#define S16_MAX_FLAGS 16

/* An OCRnx low-byte write handler (fast PWM). */
typedef struct s16_ocr_hook_t {
	struct board_model_t *bm;
	avr_timer_t *timer;
	uint16_t addr;
	io_hook_prev_t prev;
} s16_ocr_hook_t;

/* A PWM timer whose overflow is watched (OCR double buffer). */
typedef struct s16_pwm_timer_t {
	struct board_model_t *bm;
	avr_timer_t *timer;
} s16_pwm_timer_t;

/* A register with force-output-compare strobes (TCCR1C, TCCR3C). */
typedef struct s16_foc_hook_t {
	struct board_model_t *bm;
	uint16_t addr;
	io_hook_prev_t prev;
	struct bm_oc_t *oc[3];	/* the unit each strobe bit acts on */
	uint8_t bit[3];
	int n;
} s16_foc_hook_t;

/* A timer interrupt flag register (TIFR, ETIFR): which vectors' flags it holds. */
typedef struct s16_flag_reg_t {
	uint16_t addr;
	avr_int_vector_t *vec[S16_MAX_FLAGS];
	int n;
} s16_flag_reg_t;

/* The repairs' state, one per board model. */
typedef struct simavr16_timers_t {
	s16_ocr_hook_t ocr[S16_MAX_OCR];
	int nocr;
	s16_flag_reg_t flag_regs[2];
	int nflag_regs;
	s16_foc_hook_t foc[SIM_MCU_MAX_FOC];
	int nfoc;
	s16_pwm_timer_t pwm[4];
	int npwm;
} simavr16_timers_t;

/* The cycle the running cycle timer with PARAM was due at (simavr runs it
 * after the instruction that crossed it), else avr->cycle. */
uint64_t simavr16_event_cycle(avr_t *avr, void *param);

/* Whether a compare output change simavr reports for T's unit COMP is one
 * a real AVR makes. */
int simavr16_oc_event_real(avr_t *avr, const avr_timer_t *t, int comp);

/* Level-triggered INTn not polled every cycle (again after each reset). */
void simavr16_no_strict_level(avr_t *avr);

/* Hook the repairs for BM's compare units (bm->oc, found already), the
 * timers' flag registers and MCU's FOC strobes, in bm->s16. */
void simavr16_timers_init(struct board_model_t *bm, const sim_mcu_t *mcu);

#endif
