/*
 * eeprom25.c: 25LC010A-like SPI EEPROM.
 */
#include <stdio.h>
#include <string.h>

#include "parts/eeprom25.h"
#include "parts/part.h"

enum {
	EE_WRSR = 0x01, EE_WRITE = 0x02, EE_READ = 0x03, EE_WRDI = 0x04,
	EE_RDSR = 0x05, EE_WREN = 0x06,
};

static int ee_busy(const eeprom25_t *e, uint64_t cycle)
{
	return cycle < e->busy_until;
}

static uint8_t ee_status(const eeprom25_t *e, uint64_t cycle)
{
	return (uint8_t)(e->status | (e->wel ? 2 : 0) | (ee_busy(e, cycle) ? 1 : 0));
}

static void ee_reset_state(spi_dev_t *d, uint64_t cycle)
{
	eeprom25_t *e = (eeprom25_t *)d;

	(void)cycle;
	e->phase = 0;
	e->cmd = 0;
	memset(e->dirty, 0, sizeof(e->dirty));
}

static uint8_t ee_byte(spi_dev_t *d, uint8_t rx, uint64_t cycle)
{
	eeprom25_t *e = (eeprom25_t *)d;
	int phase = e->phase++;

	if (phase == 0) {
		e->cmd = rx;
		if (ee_busy(e, cycle) && rx != EE_RDSR) {
			e->cmd = 0;	/* ignored during the write cycle */
			return 0xff;
		}
		switch (rx) {
		case EE_WREN:
			e->wel = 1;
			break;
		case EE_WRDI:
			e->wel = 0;
			break;
		case EE_RDSR:
			return ee_status(e, cycle);
		default:
			break;
		}
		return 0xff;
	}
	switch (e->cmd) {
	case EE_RDSR:
		return ee_status(e, cycle);
	case EE_WRSR:
		if (phase == 1 && e->wel) {
			e->status = rx & 0x0c;
			e->cmd = 0;
			e->busy_until = cycle + EEPROM25_WRITE_CYCLES;
			e->wel = 0;
		}
		return 0xff;
	case EE_READ:
		if (phase == 1) {
			e->addr = rx & (EEPROM25_SIZE - 1);
		} else {
			e->addr = (e->addr + 1) & (EEPROM25_SIZE - 1);
		}
		return e->mem[e->addr];
	case EE_WRITE:
		if (phase == 1) {
			e->addr = rx & (EEPROM25_SIZE - 1);
		} else if (e->wel) {
			e->page[e->addr] = rx;
			e->dirty[e->addr] = 1;
			e->addr = (uint8_t)((e->addr & ~(EEPROM25_PAGE - 1)) |
					    ((e->addr + 1) & (EEPROM25_PAGE - 1)));
		}
		return 0xff;
	default:
		return 0xff;
	}
}

static void ee_end(spi_dev_t *d, uint64_t cycle)
{
	eeprom25_t *e = (eeprom25_t *)d;
	int n = 0;

	/* A write starts when CS rises on a byte boundary (rx_n == 0). */
	if (e->cmd == EE_WRITE && e->wel && d->rx_n == 0) {
		for (int i = 0; i < EEPROM25_SIZE; i++) {
			if (e->dirty[i]) {
				e->mem[i] = e->page[i];
				n++;
			}
		}
		if (n) {
			e->wel = 0;
			e->busy_until = cycle + EEPROM25_WRITE_CYCLES;
		}
	}
	memset(e->dirty, 0, sizeof(e->dirty));
	e->cmd = 0;
}

static int ee_dump(spi_dev_t *d, char *buf, int size)
{
	eeprom25_t *e = (eeprom25_t *)d;
	int n = 0;

	for (int i = 0; i < EEPROM25_SIZE && n + 3 < size; i++) {
		n += snprintf(buf + n, (size_t)(size - n), "%02X", e->mem[i]);
	}
	return n;
}

/* --- descriptor ------------------------------------------------------------ */

/* Erased (FF). */
static void eeprom25_init(void *self, const part_env_t *env)
{
	eeprom25_t *e = self;

	(void)env;
	memset(e->mem, 0xff, sizeof(e->mem));
	e->dev.byte = ee_byte;
	e->dev.reset_state = ee_reset_state;
	e->dev.end = ee_end;
	e->dev.dump = ee_dump;
	spi_dev_byte_init(&e->dev);
}

const part_kind_t eeprom25_kind = {
	.name = "eeprom25",
	.attach = PART_SPI,
	.options = "",
	.about = "a 128-byte SPI EEPROM like a 25LC010A",
	.size = sizeof(eeprom25_t),
	.init = eeprom25_init,
};
