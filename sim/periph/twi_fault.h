/*
 * twi_fault.h: faults in the middle of a byte, armed by the control socket
 * (`i2c arb BYTE BIT`, `i2c glitch start|stop BYTE BIT`; docs/simulator.md,
 * "Faults in the middle of a byte"):
 *
 *  - the rival: a driver of SDA that pulls it low for one bit, as a second
 *    master that wins arbitration there would; the master TWI (sim_twi.c)
 *    pulls it with its own clock. Where the master sends a 1 (an address
 *    or data bit it transmits, or the NACK after a byte it reads) it loses
 *    arbitration: it lets SDA go for the rest of the byte, clocks the byte
 *    to its end and reports 0x38 (or 0x68/0xB0 when the address the
 *    devices read is its own). Elsewhere the low bit is only what
 *    everybody reads: a 0 in a byte a slave sends, an ACK;
 *  - the glitch: a START or a STOP condition in SCL's high half of a bit
 *    other than the first (bit 0 is where a legal repeated START or STOP
 *    goes), told to every device's bit-level front without moving the
 *    lines (twi_bus_glitch): the master's TWI and a slave's taking part
 *    report a bus error (TW_BUS_ERROR, 0x00) and let go of the lines;
 *    every other device sees the condition as such.
 *
 * BYTE counts the bytes on the bus from the next START after arming (0:
 * its address; a repeated START's address counts as a byte); BIT is 0..7
 * for the data bits, MSB first, and 8 for the acknowledge bit. A fault
 * fires once, at its byte, and is then disarmed; a transaction that ends
 * (STOP) before its byte disarms it too.
 */
#ifndef SIM_TWI_FAULT_H
#define SIM_TWI_FAULT_H

#include <stdint.h>

typedef enum twi_fault_kind_t {
	TWI_FAULT_NONE = 0,
	TWI_FAULT_ARB,		/* the rival pulls SDA low for one bit */
	TWI_FAULT_START,	/* a START in the middle of a byte */
	TWI_FAULT_STOP,		/* a STOP in the middle of a byte */
} twi_fault_kind_t;

#define TWI_FAULT_ACK_BIT 8

typedef struct twi_fault_t {
	twi_fault_kind_t kind;
	uint8_t byte, bit;	/* where (above) */
	int counting;		/* the START after arming came */
	uint32_t seen;		/* bytes on the bus since then */
} twi_fault_t;

/* Arms KIND at BYTE, BIT (TWI_FAULT_NONE disarms). 0, or -1 for a BIT out
 * of range for KIND (the rival 0..8, a glitch 1..8). */
int twi_fault_arm(twi_fault_t *f, twi_fault_kind_t kind, unsigned byte, unsigned bit);

/* A START (or repeated START) completed: the first one after arming
 * begins the count. */
void twi_fault_on_start(twi_fault_t *f);

/* A STOP: a fault whose byte the transaction did not have is dropped.
 * 1 when one was. */
int twi_fault_on_stop(twi_fault_t *f);

/* The fault armed for the byte that begins now, or TWI_FAULT_NONE; *BIT
 * gets its bit. */
twi_fault_kind_t twi_fault_here(const twi_fault_t *f, unsigned *bit);

/* A byte ended (or was cut): the count goes on; the fault of that byte is
 * spent. */
void twi_fault_byte_done(twi_fault_t *f);

/* "arb 2 3", "glitch start 1 8" or "none", for the control socket. */
const char *twi_fault_describe(const twi_fault_t *f, char *buf, unsigned len);

#endif
