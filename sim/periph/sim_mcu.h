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

typedef struct sim_mcu_usart_t {
	uint16_t udr, ucsra, ucsrb, ubrrl;
	uint16_t ubrrh, ucsrc;	/* equal on the ATmega32: URSEL picks on write */
	uint8_t vect_rxc, vect_udre, vect_txc;
} sim_mcu_usart_t;

typedef struct sim_mcu_twi_t {
	uint16_t twbr, twsr, twar, twdr, twcr;
	uint8_t vect_twi;
} sim_mcu_twi_t;

typedef struct sim_mcu_spi_t {
	uint16_t spcr, spsr, spdr;
	uint8_t vect_spi;		/* SPI_STC */
} sim_mcu_spi_t;

/* A force-output-compare strobe: writing 1 to BIT of REG forces timer
 * TIMER's compare unit COMP (0 = A) to act on its pin (simavr 1.6 has no FOC). */
typedef struct sim_mcu_foc_t {
	char timer;		/* simavr's timer name: '1', '3' */
	uint8_t comp;
	uint16_t reg;
	uint8_t bit;
} sim_mcu_foc_t;

#define SIM_MCU_MAX_FOC 6

typedef struct sim_mcu_t {
	const char *name;	/* simavr's name: "atmega32" */
	sim_mcu_usart_t usart[2];
	uint8_t usart_count;
	sim_mcu_twi_t twi;
	sim_mcu_spi_t spi;
	sim_mcu_foc_t foc[SIM_MCU_MAX_FOC];	/* the 16-bit timers' dedicated FOC registers */
	uint8_t foc_count;
} sim_mcu_t;

/* The description of MCU NAME, or NULL if the simulator does not know it. */
const sim_mcu_t *sim_mcu_find(const char *name);

/* True when UBRRH and UCSRC share one address (URSEL selects on write). */
static inline int sim_mcu_usart_shared_ucsrc(const sim_mcu_usart_t *r)
{
	return r->ubrrh == r->ucsrc;
}

#endif
