/* SPI master on the MCU's SPI port (polled). */
#ifndef SPI_HW_H
#define SPI_HW_H

#include <stdint.h>

/* MOSI, SS outputs (SS high: master mode stays on), MISO input; SCK
 * with the first spi_hw_config(). */
void spi_hw_init(void);

/* divider: 0..6 for F_CPU/2, 4, 8, 16, 32, 64, 128; mode 0-3 (CPOL, CPHA);
 * lsb_first: bit order. */
void spi_hw_config(uint8_t divider, uint8_t mode, uint8_t lsb_first);

/* Sends buf[0..n-1], stores the bytes received in their place. */
void spi_hw_exchange(uint8_t *buf, uint8_t n);

/* The exchange's next step, if its byte is done: the byte received stored,
 * the next one sent (about 25 cycles; 6 when there is none). Called with
 * interrupts off, by the exchange and by an interrupt that waits with
 * interrupts off (the M32-D slave's servo edges, DRV_spi_WAIT()): the SPI
 * then goes on clocking bytes while it waits, instead of standing idle
 * after the byte it was clocking until the interrupt returns. */
void spi_hw_pump(void);

#endif
