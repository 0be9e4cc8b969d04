/*
 * The bus addresses a slave board or a simulated part may be given, in the
 * 8-bit form (bit 0 is the R/W bit): even, and none of the 7-bit addresses
 * I2C reserves (8-bit 0x00-0x0F and 0xF0-0xFE).
 *
 * The one place of this rule: the slave firmware checks ORFA_ADDR with it
 * (i2c_slave.c), the Makefile reads the two limits from here for ADDR=, the
 * simulator checks --slave with it, and tools/mapgen.c writes it into the
 * board maps, where the host package reads it (orfa.boardmap). Data only:
 * no avr-libc, so the host-compiled programs include it too.
 */
#ifndef ORFA_I2C_ADDR_H
#define ORFA_I2C_ADDR_H

#define I2C_ADDR_MIN 0x10
#define I2C_ADDR_MAX 0xEE

/* Whether the 8-bit address A follows the rule. */
#define I2C_ADDR_OK(a) (((a) & 1) == 0 && (a) >= I2C_ADDR_MIN && (a) <= I2C_ADDR_MAX)

#endif
