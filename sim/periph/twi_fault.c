/*
 * twi_fault.c: faults in the middle of a byte (twi_fault.h).
 */
#include <stdio.h>

#include "periph/twi_fault.h"

int twi_fault_arm(twi_fault_t *f, twi_fault_kind_t kind, unsigned byte, unsigned bit)
{
	unsigned lowest = kind == TWI_FAULT_ARB ? 0 : 1;

	if (kind != TWI_FAULT_NONE && (bit < lowest || bit > TWI_FAULT_ACK_BIT || byte > 255)) {
		return -1;
	}
	f->kind = kind;
	f->byte = (uint8_t)byte;
	f->bit = (uint8_t)bit;
	f->counting = 0;
	f->seen = 0;
	return 0;
}

void twi_fault_on_start(twi_fault_t *f)
{
	if (f->kind != TWI_FAULT_NONE && !f->counting) {
		f->counting = 1;
		f->seen = 0;
	}
}

int twi_fault_on_stop(twi_fault_t *f)
{
	if (f->kind == TWI_FAULT_NONE || !f->counting) {
		return 0;
	}
	twi_fault_arm(f, TWI_FAULT_NONE, 0, 0);
	return 1;
}

twi_fault_kind_t twi_fault_here(const twi_fault_t *f, unsigned *bit)
{
	if (f->kind == TWI_FAULT_NONE || !f->counting || f->seen != f->byte) {
		return TWI_FAULT_NONE;
	}
	*bit = f->bit;
	return f->kind;
}

void twi_fault_byte_done(twi_fault_t *f)
{
	if (f->kind == TWI_FAULT_NONE || !f->counting) {
		return;
	}
	if (f->seen == f->byte) {
		twi_fault_arm(f, TWI_FAULT_NONE, 0, 0);	/* the fault's byte: done */
		return;
	}
	f->seen++;
}

const char *twi_fault_describe(const twi_fault_t *f, char *buf, unsigned len)
{
	switch (f->kind) {
	case TWI_FAULT_ARB:
		snprintf(buf, len, "arb %u %u", f->byte, f->bit);
		break;
	case TWI_FAULT_START:
	case TWI_FAULT_STOP:
		snprintf(buf, len, "glitch %s %u %u", f->kind == TWI_FAULT_START ? "start" : "stop",
			 f->byte, f->bit);
		break;
	default:
		snprintf(buf, len, "none");
		break;
	}
	return buf;
}
