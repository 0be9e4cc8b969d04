/*
 * park_op.c: which instructions a parked loop may hold (park.h), decoded
 * from the AVR instruction set before simavr runs them.
 */
#include "harness/park_op.h"

/* A data address that is plain SRAM: no I/O handler, no IRQ (simavr passes
 * addresses below 31 + MAX_IOs through the I/O table). */
int park_plain(const avr_t *avr, uint32_t a)
{
	if (a <= avr->ioend || a > avr->ramend) {
		return 0;
	}
	if (a < 31 + MAX_IOs) {
		const avr_io_addr_t io = AVR_DATA_TO_IO(a);

		return !avr->io[io].r.c && !avr->io[io].w.c && !avr->io[io].irq;
	}
	return 1;
}

/* A load from A: SRAM, SREG, or an I/O register read without a handler
 * (its value then noted in O->io: the loop depends on it). */
static int park_read(const avr_t *avr, uint32_t a, park_op_t *o)
{
	if (a > avr->ioend) {
		o->ld[o->nld++] = (uint16_t)a;
		return park_plain(avr, a);
	}
	if (a == R_SREG) {
		return 1;
	}
	if (a < 32) {
		return 0;
	}
	const avr_io_addr_t io = AVR_DATA_TO_IO(a);

	if (avr->io[io].r.c || avr->io[io].irq) {
		return 0;
	}
	o->io = (uint16_t)a;
	return 1;
}

/* A store of V at A: plain SRAM; noted in O->st if it changes the cell. */
static int park_store(const avr_t *avr, uint32_t a, uint8_t v, park_op_t *o)
{
	if (!park_plain(avr, a)) {
		return 0;
	}
	if (avr->data[a] != v) {
		o->st[o->nst++] = (uint16_t)a;
	}
	return 1;
}

static uint16_t park_r16(const avr_t *avr, int r)
{
	return (uint16_t)(avr->data[r] | avr->data[r + 1] << 8);
}

uint16_t park_sp(const avr_t *avr)
{
	return park_r16(avr, R_SPL);
}

/* A call pushes the return address RET (words): low byte at SP, high below. */
static int park_call(const avr_t *avr, uint32_t ret, park_op_t *o)
{
	uint16_t sp = park_sp(avr);

	return park_store(avr, sp, (uint8_t)ret, o) &&
	       park_store(avr, (uint16_t)(sp - 1), (uint8_t)(ret >> 8), o);
}

/* LD/ST through X, Y or Z (with post-increment or pre-decrement) and
 * LDS/STS, PUSH/POP: the low nibble of 1001 00sd dddd xxxx. */
static int park_ldst(const avr_t *avr, uint16_t op, uint16_t op2, park_op_t *o)
{
	int d = (op >> 4) & 0x1f, store = op & 0x0200;
	uint32_t a;

	switch (op & 0x000f) {
	case 0x0: a = op2; break;				/* LDS, STS */
	case 0x1: a = park_r16(avr, 30); break;			/* Z+ */
	case 0x2: a = (uint16_t)(park_r16(avr, 30) - 1); break;	/* -Z */
	case 0x9: a = park_r16(avr, 28); break;			/* Y+ */
	case 0xa: a = (uint16_t)(park_r16(avr, 28) - 1); break;	/* -Y */
	case 0xc: case 0xd: a = park_r16(avr, 26); break;	/* X, X+ */
	case 0xe: a = (uint16_t)(park_r16(avr, 26) - 1); break;	/* -X */
	case 0xf: a = store ? park_sp(avr) : park_sp(avr) + 1u; break;	/* PUSH, POP */
	case 0x4: case 0x5: case 0x6: case 0x7:
		return !store;					/* LPM, ELPM Z(+) */
	default:
		return 0;
	}
	return store ? park_store(avr, a, avr->data[d], o) : park_read(avr, a, o);
}

/* 1001 0101 xxxx 1000 and 1001 0100 sss 1000: returns, SLEEP, WDR, LPM,
 * SREG bits (not I). */
static int park_misc(const avr_t *avr, uint16_t op, park_op_t *o)
{
	uint16_t sp = park_sp(avr);

	switch (op) {
	case 0x9508:	/* RET */
		return park_read(avr, sp + 1u, o) && park_read(avr, sp + 2u, o);
	case 0x95a8:	/* WDR */
		o->wdr = 1;
		return 1;
	case 0x95c8:	/* LPM */
	case 0x95d8:	/* ELPM */
		return 1;
	case 0x9478:	/* SEI */
	case 0x94f8:	/* CLI */
		return 0;
	default:	/* BSET/BCLR of another flag; RETI, SLEEP, BREAK, SPM: no */
		return (op & 0xff0f) == 0x9408;
	}
}

/* 1001 xxxx xxxx xxxx. */
static int park_op9(const avr_t *avr, avr_flashaddr_t pc, uint16_t op, uint16_t op2,
		    park_op_t *o)
{
	if ((op & 0xfc00) == 0x9000) {
		return park_ldst(avr, op, op2, o);
	}
	if ((op & 0xfe00) == 0x9400) {
		switch (op & 0x000f) {
		case 0x0: case 0x1: case 0x2: case 0x3:	/* COM NEG SWAP INC */
		case 0x5: case 0x6: case 0x7: case 0xa:	/* ASR LSR ROR DEC */
		case 0xc: case 0xd:			/* JMP */
			return 1;
		case 0xe: case 0xf:			/* CALL */
			return park_call(avr, (pc + 4) >> 1, o);
		case 0x8:
			return park_misc(avr, op, o);
		case 0x9:
			if (op == 0x9409) {		/* IJMP */
				return 1;
			}
			return op == 0x9509 && park_call(avr, (pc + 2) >> 1, o);	/* ICALL */
		default:
			return 0;
		}
	}
	if ((op & 0xfe00) == 0x9600) {			/* ADIW, SBIW */
		return 1;
	}
	if ((op & 0xfd00) == 0x9900) {			/* SBIC, SBIS */
		return park_read(avr, ((op >> 3) & 0x1fu) + 32u, o);
	}
	return (op & 0xfc00) == 0x9c00;			/* MUL; not CBI, SBI */
}

int park_op_ok(const avr_t *avr, avr_flashaddr_t pc, park_op_t *o)
{
	uint16_t op, op2;

	if (pc + 3 >= avr->flashend) {
		return 0;
	}
	op = (uint16_t)(avr->flash[pc] | avr->flash[pc + 1] << 8);
	op2 = (uint16_t)(avr->flash[pc + 2] | avr->flash[pc + 3] << 8);
	switch (op & 0xf000) {
	case 0x8000: case 0xa000: {			/* LDD, STD (Y/Z + q) */
		uint16_t q = (uint16_t)(((op >> 8) & 0x20) | ((op >> 7) & 0x18) | (op & 7));
		uint32_t a = park_r16(avr, (op & 8) ? 28 : 30) + q;

		return (op & 0x0200) ? park_store(avr, a, avr->data[(op >> 4) & 0x1f], o) :
		       park_read(avr, a, o);
	}
	case 0x9000:
		return park_op9(avr, pc, op, op2, o);
	case 0xb000:					/* IN; not OUT */
		return !(op & 0x0800) && park_read(avr, (((op >> 5) & 0x30u) | (op & 0xfu)) + 32u, o);
	case 0xd000:					/* RCALL */
		return park_call(avr, (pc + 2) >> 1, o);
	default:	/* register and immediate ALU, branches, skips, RJMP, LDI */
		return 1;
	}
}
