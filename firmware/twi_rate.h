/* TWI bit-rate arithmetic (pure, host-tested): SCL = F_CPU / (16 + 2·TWBR·4^TWPS). */
#ifndef ORFA_TWI_RATE_H
#define ORFA_TWI_RATE_H

#include <stdint.h>

typedef struct {
	uint8_t twbr;
	uint8_t twps;      /* prescaler bits: 4^twps */
	uint32_t period;   /* SCL period in CPU cycles */
	uint16_t khz;      /* the rate made, kHz rounded down */
} twi_rate_t;

/* The fastest rate not above `khz` (smallest prescaler that reaches it). */
twi_rate_t twi_rate_for_khz(uint32_t f_cpu, uint16_t khz);

#endif
