#include "drivers/drv_spi.h"

#include <string.h>

#include "board.h"
#include "drivers/spi_hw.h"
#include "firmware/board_pins.h"
#include "firmware/pins.h"

#define SPI_REG_DATA 0
#define SPI_REG_CONFIG 1
#define SPI_UNBOUND 0xFF
#define SPI_BUS 0xFF

/* GPIO port indices, as CONFIG numbers them (the GPIO driver's ports). */
static const ORFA_FLASH uint8_t spi_ports[] = {
#define X(letter) (uint8_t)((letter) - 'A'),
	BOARD_GPIO_PORTS(X)
#undef X
};
#define SPI_NPORTS ((uint8_t)sizeof spi_ports)

static struct {
	uint8_t cs[SPI_CHANNELS];   /* chip-select pin (PIN_ID) or SPI_UNBOUND */
	uint8_t settings;
	uint8_t rx_len;             /* bytes of the last exchange, 0 = none yet */
	uint8_t rx[SPI_BUF];
} spi;

static void spi_apply(uint8_t settings)
{
	spi_hw_config(settings & SPI_SET_DIV_MASK, (uint8_t)((settings >> SPI_SET_MODE_SHIFT) & 3),
		      settings & SPI_SET_LSB_FIRST);
}

void drv_spi_init(void)
{
	for (uint8_t i = 0; i < SPI_CHANNELS; i++) {
		spi.cs[i] = SPI_UNBOUND;
	}
	spi.rx_len = 0;
	spi.settings = SPI_SET_DEFAULT;
	pins_claim(board_pin_at(BF_SPI_SS, 0), PIN_SPI);
	pins_claim(board_pin_at(BF_SPI_SCK, 0), PIN_SPI);
	pins_claim(board_pin_at(BF_SPI_MOSI, 0), PIN_SPI);
	pins_claim(board_pin_at(BF_SPI_MISO, 0), PIN_SPI);
	spi_hw_init();
	spi_apply(spi.settings);
}

/* [channel][port][line]: bind a chip-select line; [FF][x][settings]: bus. */
static reg_status_t spi_config(const uint8_t *data, uint8_t len)
{
	if (len != 3) {
		return REG_BAD_LENGTH;
	}
	if (data[0] == SPI_BUS) {
		if (data[2] & 0xC0) {
			return REG_BAD_VALUE;
		}
		spi.settings = data[2];
		spi_apply(spi.settings);
		return REG_OK;
	}
	uint8_t ch = data[0];
	if (ch >= SPI_CHANNELS || data[1] >= SPI_NPORTS || data[2] > 7) {
		return REG_BAD_VALUE;
	}
	uint8_t pin = (uint8_t)(spi_ports[data[1]] * 8 + data[2]);
	if (spi.cs[ch] == pin) {
		return REG_OK;
	}
	for (uint8_t i = 0; i < SPI_CHANNELS; i++) {
		if (spi.cs[i] == pin) {
			return REG_PIN_BUSY;  /* another channel's chip select */
		}
	}
	if (!pins_claim(pin, PIN_SPI_CS)) {
		return REG_PIN_BUSY;
	}
	if (spi.cs[ch] != SPI_UNBOUND) {
		pins_release(spi.cs[ch], PIN_SPI_CS);
	}
	spi.cs[ch] = pin;
	pins_drive(pin, true);  /* deselected */
	return REG_OK;
}

/* [channel][bytes...]: select, exchange, deselect. */
static reg_status_t spi_data(const uint8_t *data, uint8_t len)
{
	if (len < 2 || len - 1 > SPI_BUF) {
		return REG_BAD_LENGTH;
	}
	if (data[0] >= SPI_CHANNELS) {
		return REG_BAD_VALUE;
	}
	uint8_t pin = spi.cs[data[0]];
	if (pin == SPI_UNBOUND) {
		return REG_NOT_BOUND;
	}
	uint8_t n = (uint8_t)(len - 1);
	memcpy(spi.rx, data + 1, n);
	pins_level(pin, false);
	spi_hw_exchange(spi.rx, n);
	pins_level(pin, true);
	spi.rx_len = n;
	return REG_OK;
}

reg_status_t drv_spi_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)data;
	if (reg == SPI_REG_CONFIG) {
		return len > 3 ? REG_BAD_LENGTH : REG_OK;
	}
	return len - 1 > SPI_BUF ? REG_BAD_LENGTH : REG_OK;  /* channel, bytes */
}

reg_status_t drv_spi_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	return reg == SPI_REG_CONFIG ? spi_config(data, len) : spi_data(data, len);
}

/* DATA: the bytes received in the last exchange. CONFIG: [settings] then
 * each channel's [port][line] (FF FF when unbound). */
uint8_t drv_spi_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	uint8_t cfg[1 + 2 * SPI_CHANNELS];
	const uint8_t *src = spi.rx;
	uint8_t n = spi.rx_len;

	if (reg != SPI_REG_DATA) {
		cfg[0] = spi.settings;
		for (uint8_t i = 0; i < SPI_CHANNELS; i++) {
			uint8_t port = SPI_UNBOUND;
			uint8_t line = SPI_UNBOUND;
			if (spi.cs[i] != SPI_UNBOUND) {
				for (uint8_t p = 0; p < SPI_NPORTS; p++) {
					if (spi_ports[p] == PIN_PORT(spi.cs[i])) {
						port = p;
					}
				}
				line = spi.cs[i] & 7;
			}
			cfg[1 + 2 * i] = port;
			cfg[2 + 2 * i] = line;
		}
		src = cfg;
		n = sizeof cfg;
	}
	/* one copy for both */
	if (n > max) {
		n = max;
	}
	memcpy(dst, src, n);
	return n;
}
