/*
 * eeprom25.h: a 128-byte SPI EEPROM like a 25LC010A, SPI mode 0 (it also
 * works in mode 3 on silicon; the model declares one mode), MSB first.
 *
 *   WREN 06, WRDI 04: set/clear the write enable latch (WEL)
 *   RDSR 05: status byte, bit 0 WIP, bit 1 WEL, bits 2-3 BP (repeats)
 *   WRSR 01 s: block protect bits BP1:BP0 (stored, not enforced)
 *   READ 03 a: data from address a (7 bits), auto-increment, wraps at 128
 *   WRITE 02 a d...: needs WEL; bytes wrap inside the 16-byte page; the
 *       page is written when CS rises after a whole byte, then WIP is set
 *       for EEPROM25_WRITE_CYCLES and WEL cleared. While WIP only RDSR works.
 */
#ifndef SIM_PARTS_EEPROM25_H
#define SIM_PARTS_EEPROM25_H

#include "periph/spi.h"

#define EEPROM25_SIZE 128
#define EEPROM25_PAGE 16
#define EEPROM25_WRITE_CYCLES 36864u	/* 5 ms at 7.3728 MHz */

typedef struct eeprom25_t {
	spi_dev_t dev;			/* first */
	uint8_t mem[EEPROM25_SIZE];
	uint8_t page[EEPROM25_SIZE];	/* write buffer */
	uint8_t dirty[EEPROM25_SIZE];
	uint8_t cmd, addr, status;	/* status: BP bits */
	int phase;			/* bytes of this selection */
	int wel;
	uint64_t busy_until;
	uint64_t (*now)(void *);
} eeprom25_t;

#endif
