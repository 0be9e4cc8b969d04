/*
 * mcu.h: the MCU layer of the simulator. Data-space addresses of the
 * registers the simulator models itself (USART, TWI, SPI) and their vector
 * numbers, per MCU. Checked against avr-libc's iom32.h / iom128.h
 * (data address = I/O address + 0x20 for _SFR_IO8 registers).
 */
#ifndef SIM_MCU_H
#define SIM_MCU_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_io.h"

typedef struct mcu_usart_regs_t {
	uint16_t udr, ucsra, ucsrb, ubrrl;
	uint16_t ubrrh, ucsrc;	/* equal on the ATmega32: URSEL picks on write */
	uint8_t vect_rxc, vect_udre, vect_txc;
} mcu_usart_regs_t;

typedef struct mcu_twi_regs_t {
	uint16_t twbr, twsr, twar, twdr, twcr;
	uint8_t vect_twi;
} mcu_twi_regs_t;

typedef struct mcu_spi_regs_t {
	uint16_t spcr, spsr, spdr;
	uint8_t vect_spi;		/* SPI_STC */
} mcu_spi_regs_t;

/* A force-output-compare strobe: writing 1 to BIT of REG forces timer
 * TIMER's compare unit COMP (0 = A) to act on its pin (simavr 1.6 has no FOC). */
typedef struct mcu_foc_t {
	char timer;		/* simavr's timer name: '1', '3' */
	uint8_t comp;
	uint16_t reg;
	uint8_t bit;
} mcu_foc_t;

#define MCU_MAX_FOC 6

typedef struct mcu_desc_t {
	const char *name;	/* simavr's name: "atmega32" */
	mcu_usart_regs_t usart[2];
	uint8_t usart_count;
	mcu_twi_regs_t twi;
	mcu_spi_regs_t spi;
	mcu_foc_t foc[MCU_MAX_FOC];	/* the 16-bit timers' dedicated FOC registers */
	uint8_t foc_count;
} mcu_desc_t;

/* The description of MCU NAME, or NULL if the simulator does not know it. */
const mcu_desc_t *mcu_find(const char *name);

/* True when UBRRH and UCSRC share one address (URSEL selects on write). */
static inline int mcu_usart_shared_ucsrc(const mcu_usart_regs_t *r)
{
	return r->ubrrh == r->ucsrc;
}

/* Register IO at the END of simavr's module list, so that its reset hook
 * runs after simavr's own USART/TWI resets and has the last word on the
 * registers the simulator owns (avr_register_io puts it first). */
void mcu_register_io_last(avr_t *avr, avr_io_t *io);

#endif
