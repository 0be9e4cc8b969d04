/*
 * park_op.h: which instructions a parked loop may hold (park.h): register
 * and immediate arithmetic, branches, skips, calls and returns, loads from
 * SRAM, flash, SREG and I/O registers without a read handler, stores to
 * SRAM, WDR. Not: writes to I/O registers, the I bit (SEI, CLI, RETI),
 * SLEEP, SPM, BREAK, reads of I/O registers that have a handler.
 */
#ifndef SIM_PARK_OP_H
#define SIM_PARK_OP_H

#include <stdint.h>

#include "sim_avr.h"

/* What an instruction does besides registers and SRAM. */
typedef struct park_op_t {
	int wdr;		/* it is a WDR */
	uint16_t io;		/* the I/O register it reads (0: none) */
	uint16_t ld[2];		/* the SRAM cells it reads */
	int nld;
	uint16_t st[2];		/* the SRAM cells it changes (a value not there yet) */
	int nst;
} park_op_t;

/* A data address that is plain SRAM: no I/O handler, no IRQ. */
int park_plain(const avr_t *avr, uint32_t a);

/* The stack pointer. */
uint16_t park_sp(const avr_t *avr);

/* May the instruction at PC be in a parked loop? What it does besides
 * registers goes to O (O->nld, O->nst zeroed by the caller). */
int park_op_ok(const avr_t *avr, avr_flashaddr_t pc, park_op_t *o);

#endif
