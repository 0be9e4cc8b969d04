/*
 * mcu.c: per-MCU register addresses and vectors.
 */
#include <string.h>

#include "periph/sim_mcu.h"

static const sim_mcu_t mcu_table[] = {
	{
		.name = "atmega32",
		.usart = {
			{
				.udr = 0x2c, .ucsra = 0x2b, .ucsrb = 0x2a, .ubrrl = 0x29,
				.ubrrh = 0x40, .ucsrc = 0x40,
				.vect_rxc = 13, .vect_udre = 14, .vect_txc = 15,
			},
		},
		.usart_count = 1,
		.twi = {
			.twbr = 0x20, .twsr = 0x21, .twar = 0x22, .twdr = 0x23,
			.twcr = 0x56, .vect_twi = 19,
		},
		.spi = { .spcr = 0x2d, .spsr = 0x2e, .spdr = 0x2f, .vect_spi = 12 },
	},
	{
		.name = "atmega128",
		.usart = {
			{	/* USART0 */
				.udr = 0x2c, .ucsra = 0x2b, .ucsrb = 0x2a, .ubrrl = 0x29,
				.ubrrh = 0x90, .ucsrc = 0x95,
				.vect_rxc = 18, .vect_udre = 19, .vect_txc = 20,
			},
			{	/* USART1 */
				.udr = 0x9c, .ucsra = 0x9b, .ucsrb = 0x9a, .ubrrl = 0x99,
				.ubrrh = 0x98, .ucsrc = 0x9d,
				.vect_rxc = 30, .vect_udre = 31, .vect_txc = 32,
			},
		},
		.usart_count = 2,
		.twi = {
			.twbr = 0x70, .twsr = 0x71, .twar = 0x72, .twdr = 0x73,
			.twcr = 0x74, .vect_twi = 33,
		},
		.spi = { .spcr = 0x2d, .spsr = 0x2e, .spdr = 0x2f, .vect_spi = 17 },
		.foc = {	/* TCCR1C, TCCR3C: FOCnA/B/C = bits 7/6/5 */
			{ '1', 0, 0x7a, 7 }, { '1', 1, 0x7a, 6 }, { '1', 2, 0x7a, 5 },
			{ '3', 0, 0x8c, 7 }, { '3', 1, 0x8c, 6 }, { '3', 2, 0x8c, 5 },
		},
		.foc_count = 6,
	},
};

const sim_mcu_t *sim_mcu_find(const char *name)
{
	for (unsigned i = 0; i < sizeof(mcu_table) / sizeof(mcu_table[0]); i++) {
		if (strcmp(mcu_table[i].name, name) == 0) {
			return &mcu_table[i];
		}
	}
	return NULL;
}
