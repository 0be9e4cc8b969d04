/*
 * fault.c: a hung firmware and the resets of the control socket.
 */
#include <string.h>

#include "sim_regbit.h"

#include "harness/fault.h"

/* MCUCSR on both MCUs (I/O 0x34), should simavr not name the flags. */
#define FAULT_MCUCSR 0x54

/* rjmp .-2, little-endian */
#define FAULT_LOOP_LO 0xFF
#define FAULT_LOOP_HI 0xCF

int fault_hang(avr_t *avr)
{
	uint32_t at = avr->flashend - 1u;	/* byte address of the top word */

	if (avr->codeend && avr->codeend > at) {
		return -1;
	}
	avr->flash[at] = FAULT_LOOP_LO;
	avr->flash[at + 1] = FAULT_LOOP_HI;
	avr->sreg[S_I] = 0;
	avr->pc = at;
	avr->state = cpu_Running;
	return 0;
}

static void fault_flag(avr_t *avr, avr_regbit_t rb, uint8_t bit)
{
	if (rb.reg) {
		avr_regbit_set(avr, rb);
	} else {
		avr->data[FAULT_MCUCSR] |= (uint8_t)(1u << bit);
	}
}

int fault_reset(avr_t *avr, board_model_t *bm, const char *cause)
{
	if (!strcmp(cause, "power")) {
		/* What SRAM holds at power-up is anybody's guess: noise, then
		 * the board model's paint (board_model.c) over it. */
		uint32_t x = (uint32_t)avr->cycle | 1u;

		for (uint32_t a = avr->ioend + 1u; a <= avr->ramend; a++) {
			x ^= x << 13;
			x ^= x >> 17;
			x ^= x << 5;
			avr->data[a] = (uint8_t)x;
		}
	} else if (strcmp(cause, "external") != 0 && strcmp(cause, "brownout") != 0) {
		return -1;
	}
	bm->reset_cause = cause;
	avr_reset(avr);
	bm->reset_cause = NULL;
	avr->state = cpu_Running;
	if (!strcmp(cause, "power")) {
		fault_flag(avr, avr->reset_flags.porf, 0);
	} else if (!strcmp(cause, "external")) {
		fault_flag(avr, avr->reset_flags.extrf, 1);
	} else {
		fault_flag(avr, avr->reset_flags.borf, 2);
	}
	return 0;
}
