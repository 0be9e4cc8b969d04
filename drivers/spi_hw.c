#include "drivers/spi_hw.h"

#include <avr/io.h>
#include <util/atomic.h>

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

/* The exchange under way: where the byte on the wire comes back to (the
 * next one to send follows it) and how many are still to come back. */
static struct {
	uint8_t *at;
	volatile uint8_t left;
} run;

/* Its byte done (SPIF): the next one sent, then the one received stored
 * (SPDR keeps it for reading until the next one has come in: the receive
 * side is double buffered). Interrupts off. */
static inline __attribute__((always_inline)) void spi_step(void)
{
	uint8_t *p = run.at;
	uint8_t left = (uint8_t)(run.left - 1);
	if (left) {
		SPDR = p[1];
	}
	run.left = left;
	*p++ = SPDR;
	run.at = p;
}

void spi_hw_pump(void)
{
	if (run.left && (SPSR & _BV(SPIF))) {
		spi_step();
	}
}

void spi_hw_exchange(uint8_t *buf, uint8_t n)
{
	if (!n) {
		return;
	}
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
		run.at = buf;
		run.left = n;
		SPDR = *buf;
	}
	/* Each byte goes on where its end is seen first: here, or in an
	 * interrupt that waits with interrupts off (spi_hw_pump()). The master
	 * clocks a byte itself, at most 8 * 128 cycles: one that never ends
	 * (the SPI off, or made a slave) ends the exchange after 65536 looks. */
	uint16_t guard = 0;
	while (run.left) {
		if (SPSR & _BV(SPIF)) {
			ATOMIC_BLOCK(ATOMIC_RESTORESTATE) {
				if (SPSR & _BV(SPIF)) {  /* not taken by an interrupt meanwhile */
					spi_step();
				}
			}
			guard = 0;
		} else if (!++guard) {
			run.left = 0;  /* nothing more for the interrupt either */
		}
	}
}
