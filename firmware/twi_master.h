/*
 * TWI (I2C) master, polled, with a time bound on every step (clock.h ticks:
 * about 9 ms plus the step's own bus time) so that a missing or stuck
 * device gives an error within 10 ms, never a hang. A step that fails (times
 * out, loses arbitration, sees a bus error) abandons the transaction: the
 * TWI is reset (TWBR/TWPS kept), no STOP is sent, and nothing goes on the
 * bus again until a slave has dropped the frame (twi_quiet.h), as after
 * this board's own reset.
 */
#ifndef ORFA_TWI_MASTER_H
#define ORFA_TWI_MASTER_H

#include <stdbool.h>
#include <stdint.h>

typedef enum {
	TWI_ACK = 0,   /* the byte was acknowledged */
	TWI_NACK,      /* it was not */
	TWI_FAIL,      /* bus error, arbitration lost or timeout: abandoned */
} twi_result_t;

/* The TWI on, the quiet fence up; twi_set_khz() then, before a transfer. */
void twi_init(void);

/* Sets the fastest SCL rate the TWI can make that is not above `khz` and
 * returns that rate in kHz, rounded down. */
uint16_t twi_set_khz(uint16_t khz);

/* START (or repeated START) and the address byte (8-bit form, bit 0 = read);
 * first waits out the quiet fence if it is up. */
twi_result_t twi_start(uint8_t addr8);
/* The n data bytes of a write frame, up to the first one not acknowledged
 * (TWI_NACK) or a failed step (TWI_FAIL). */
twi_result_t twi_write_bytes(const uint8_t *data, uint8_t n);
/* The n data bytes of a read frame, each acknowledged but the last (the
 * slave sends no more); TWI_FAIL when a step fails. */
twi_result_t twi_read_bytes(uint8_t *data, uint8_t n);
/* From the front end's idle loop: lets the quiet fence come down when its
 * time is over (cheap: one byte test while it is down). */
void twi_idle(void);

/* STOP, ending the transaction. False when it could not be put on the bus
 * (a step timed out: abandoned, the frame is dropped by its slave); true
 * when it was, or the transaction was abandoned already. */
bool twi_stop(void);

/* Frees a bus held by a slave: after the quiet fence, clocks SCL until SDA
 * is released (at most 9 clocks), then a STOP; the TWI is re-enabled afterwards (clock kept).
 * True when both lines are high at the end, false when SDA stayed low
 * after nine clocks or SCL is held low. */
bool twi_clear_bus(void);

#endif
