/*
 * mcp3008.h: an MCP3008-like 8-channel 10-bit SPI ADC (mode 0 by default),
 * reading the board's analog inputs (the same voltages as the MCU's ADC
 * port) against VREF = the board's AVCC.
 *
 * Bit level, as in the datasheet: after CS falls the first 1 clocked in is
 * the start bit, then SGL/DIFF, D2, D1, D0; one more clock samples; then
 * DOUT gives a null bit (0) and B9..B0 MSB first, then B1..B9 LSB first,
 * then zeros. DOUT is high (undriven) before the null bit. Code =
 * 1024 * Vin / VREF, clipped to 1023; differential = IN+ - IN-, 0 if negative.
 * With the usual 3-byte exchange 01, S D2 D1 D0 x x x x, 00 the result is the
 * low 2 bits of the second reply byte and the third byte.
 */
#ifndef SIM_PARTS_MCP3008_H
#define SIM_PARTS_MCP3008_H

#include "periph/spi.h"

typedef struct mcp3008_t {
	spi_dev_t dev;			/* first */
	const uint32_t *mv;		/* 8 channel voltages, mV */
	const uint32_t *vref;		/* mV */
	int state;			/* 0 wait start, 1..4 config bits, 5 sample, 6 out */
	uint8_t config;
	uint16_t code;
	int out_n;			/* bits given since the null bit */
	int last_code;
} mcp3008_t;

#endif
