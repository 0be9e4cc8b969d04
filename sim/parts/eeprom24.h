/*
 * eeprom24.h: a 256-byte serial EEPROM like a 24C02 on the simulated I2C
 * bus. One word-address byte; reads auto-increment and wrap at 256; writes
 * wrap inside their 8-byte page and are committed at the STOP; ready again
 * at once (no write cycle time).
 */
#ifndef SIM_PARTS_EEPROM24_H
#define SIM_PARTS_EEPROM24_H

#include <stdint.h>

#include "periph/twi_bus.h"

#define EEPROM24_SIZE 256
#define EEPROM24_PAGE 8

typedef struct eeprom24_t {
	twi_dev_t dev;			/* first: the bus's view */
	uint8_t addr8;			/* 8-bit bus address, R/W bit clear */
	uint8_t mem[EEPROM24_SIZE];
	uint8_t ptr;			/* word address counter */
	uint8_t selected;		/* addressed since the last START */
	uint8_t want_word_addr;		/* next written byte is the word address */
	uint8_t write_protect;		/* WP high: data bytes are not acknowledged */
} eeprom24_t;

#endif
