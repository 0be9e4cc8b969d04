#include "drivers/spi_hw.h"

#include <avr/io.h>

#include "firmware/board_pins.h"
#include "firmware/mcu.h"
#include "firmware/pins.h"

/* The SPI pins are the MCU's own (port B on both boards), known when
 * compiling: each step is one sbi/cbi on the port's register, which no
 * interrupt can come between (the servo interrupt drives other lines of
 * the port), as port_io's read-modify-writes with interrupts off. */
static inline __attribute__((always_inline)) void spi_pin(uint8_t pin, uint8_t output, uint8_t level)
{
	mcu_port_t p = mcu_port_at(PIN_PORT(pin));
	uint8_t mask = PIN_MASK(pin);
	if (level) {
		*p.port |= mask;
	} else {
		*p.port &= (uint8_t)~mask;
	}
	if (output) {
		*p.ddr |= mask;
	} else {
		*p.ddr &= (uint8_t)~mask;
	}
}

/* The settings (and SCK's idle level) are the driver's first
 * spi_hw_config(), right after. */
void spi_hw_init(void)
{
	spi_pin(board_pin_at(BF_SPI_SS, 0), 1, 1);
	spi_pin(board_pin_at(BF_SPI_MOSI, 0), 1, 0);
	spi_pin(board_pin_at(BF_SPI_MISO, 0), 0, 0);
}

void spi_hw_config(uint8_t divider, uint8_t mode, uint8_t lsb_first)
{
	/* divider 0..6 = /2 /4 /8 /16 /32 /64 /128: SPR = divider / 2, and
	 * SPI2X doubles the rate for the even steps below /128 (datasheet table
	 * "Relationship between SCK and the oscillator frequency"). */
	uint8_t spr = (uint8_t)(divider >> 1);
	uint8_t spcr = _BV(SPE) | _BV(MSTR) | (spr & 3);
	if (mode & 2) {
		spcr |= _BV(CPOL);
	}
	if (mode & 1) {
		spcr |= _BV(CPHA);
	}
	if (lsb_first) {
		spcr |= _BV(DORD);
	}
	SPCR = spcr;
	SPSR = (!(divider & 1) && divider < 6) ? _BV(SPI2X) : 0;
	/* SCK idles at CPOL: give the pin that level while SPI is off too. */
	spi_pin(board_pin_at(BF_SPI_SCK, 0), 1, (uint8_t)(mode & 2));
}

void spi_hw_exchange(uint8_t *buf, uint8_t n)
{
	for (uint8_t i = 0; i < n; i++) {
		SPDR = buf[i];
		/* Master clocks the byte itself: at most 8 * 128 cycles. */
		uint16_t guard = 0;
		while (!(SPSR & _BV(SPIF)) && ++guard) {
		}
		buf[i] = SPDR;
	}
}
