/* SPI driver (UID 0x0001): DATA (R) and CONFIG (R+1). */
#ifndef DRV_SPI_H
#define DRV_SPI_H

#include "drivers/spi_hw.h"
#include "firmware/regmap.h"

#define DRV_spi_NREGS 2
#define DRV_spi_REGS(X) X("DATA", 0) X("CONFIG", 0)
#define SPI_CHANNELS 4
#define SPI_BUF 64

/* CONFIG [FF][x][settings]: bits 0-2 clock divider (F_CPU/2 << n, n = 0..6),
 * bits 3-4 SPI mode (bit 4 CPOL, bit 3 CPHA), bit 5 LSB first. */
#define SPI_SET_DIV_MASK  0x07
#define SPI_SET_MODE_SHIFT 3
#define SPI_SET_LSB_FIRST 0x20
#define SPI_SET_DEFAULT   0x02  /* F_CPU/8 = 921.6 kHz, mode 0, MSB first */

#define DRV_spi_UID 0x0001
#define DRV_spi_MAJOR 1
#define DRV_spi_MINOR 1
/* The link-loss failsafe leaves it as it is. */
#define DRV_spi_SAFE() ((void)0)
#define DRV_spi_LATER() ((void)0)
/* An exchange goes on while an interrupt waits (spi_hw.h). */
#define DRV_spi_WAIT() spi_hw_pump()

REGMAP_DRIVER_API(spi);

#endif
