/*
 * eeprom24lc32.c: a Microchip 24LC32A, a 4 KB (4096 x 8) serial EEPROM, on
 * the simulated I2C bus, after its datasheet (DS21713):
 *  - 8-bit addresses A0..AE (control code 1010, chip selects A2..A0);
 *  - two word-address bytes, high first; the upper four bits of the high
 *    one are "don't care" (the address is 12 bits);
 *  - writes: a byte or a page of up to 32 bytes; the address counter's
 *    low 5 bits roll over inside the page (more than 32 bytes overwrite
 *    the first ones); the bytes are written in a write cycle that starts
 *    at the STOP and lasts tWC (5 ms, the datasheet's maximum), during
 *    which the chip does not acknowledge its address (acknowledge polling);
 *    a STOP after the word address alone starts no write cycle;
 *  - reads: current address, random (the word address, then a repeated
 *    START) and sequential; the counter moves on after each byte read and
 *    rolls over from 0xFFF to 0x000; it is kept across STOP (a current
 *    address read goes on from the last byte accessed, plus one);
 *  - WP high (option `wp`): the array is write-protected: data bytes are
 *    still acknowledged, no write cycle follows and nothing is written
 *    (the datasheet's words; the AT24C parts of --eeprom :wp NACK them).
 * Assumed where the datasheet is silent: a repeated START after data bytes
 * abandons them (the write cycle needs a STOP); erased bytes read FF.
 */
#include <string.h>

#include "parts/part.h"
#include "periph/twi_bus.h"

#define EE24LC32_SIZE 4096
#define EE24LC32_PAGE 32
#define EE24LC32_TWC_US 5000

typedef struct ee24lc32_t {
	twi_dev_t dev;			/* first: the bus's view */
	const twi_bus_t *bus;		/* its `cycle` is the time of an event */
	uint32_t hz;
	uint8_t addr8;
	uint8_t write_protect;		/* WP high */
	uint8_t selected;		/* addressed since the last START */
	uint8_t addr_bytes;		/* word-address bytes still expected: 2, 1, 0 */
	uint8_t addr_hi;
	uint16_t ptr;			/* the address counter */
	uint8_t page[EE24LC32_PAGE];	/* data of the write under way */
	uint32_t pending;		/* bit per byte of page[] received */
	uint16_t page_base;
	uint64_t busy_until;		/* the write cycle ends at this cycle */
	uint8_t mem[EE24LC32_SIZE];
} ee24lc32_t;

static int ee24lc32_start(twi_dev_t *dev, uint8_t addr8)
{
	ee24lc32_t *e = (ee24lc32_t *)dev;

	e->selected = (addr8 & 0xfe) == e->addr8 && e->bus->cycle >= e->busy_until;
	e->addr_bytes = e->selected && !(addr8 & 1) ? 2 : 0;
	e->pending = 0;		/* a repeated START drops data without a STOP */
	return e->selected;
}

static int ee24lc32_write(twi_dev_t *dev, uint8_t byte)
{
	ee24lc32_t *e = (ee24lc32_t *)dev;

	if (!e->selected) {
		return 0;
	}
	if (e->addr_bytes == 2) {
		e->addr_hi = byte & 0x0f;
		e->addr_bytes = 1;
		return 1;
	}
	if (e->addr_bytes == 1) {
		e->ptr = (uint16_t)(e->addr_hi << 8 | byte);
		e->page_base = e->ptr & (uint16_t)~(EE24LC32_PAGE - 1);
		e->addr_bytes = 0;
		return 1;
	}
	e->page[e->ptr % EE24LC32_PAGE] = byte;
	e->pending |= 1u << (e->ptr % EE24LC32_PAGE);
	e->ptr = (uint16_t)(e->page_base | ((e->ptr + 1) % EE24LC32_PAGE));
	return 1;
}

static uint8_t ee24lc32_read(twi_dev_t *dev)
{
	ee24lc32_t *e = (ee24lc32_t *)dev;
	uint8_t v = e->mem[e->ptr];

	e->ptr = (e->ptr + 1) % EE24LC32_SIZE;
	return v;
}

static void ee24lc32_stop(twi_dev_t *dev)
{
	ee24lc32_t *e = (ee24lc32_t *)dev;

	if (e->selected && e->pending && !e->write_protect) {
		for (int i = 0; i < EE24LC32_PAGE; i++) {
			if (e->pending & (1u << i)) {
				e->mem[e->page_base + i] = e->page[i];
			}
		}
		e->busy_until = e->bus->cycle + (uint64_t)e->hz * EE24LC32_TWC_US / 1000000u;
	}
	e->pending = 0;
	e->selected = 0;
	e->addr_bytes = 0;
}

static const twi_dev_ops_t ee24lc32_ops = {
	.start = ee24lc32_start,
	.write = ee24lc32_write,
	.read = ee24lc32_read,
	.stop = ee24lc32_stop,
};

/* --- descriptor ------------------------------------------------------------ */

static void ee24lc32_part_init(void *self, const part_env_t *env)
{
	ee24lc32_t *e = self;

	e->dev.ops = &ee24lc32_ops;
	e->bus = env->bus;
	e->hz = env->hz;
	e->addr8 = env->addr8 & 0xfe;
	e->write_protect = !strcmp(env->opts, "wp");
	memset(e->mem, 0xff, sizeof(e->mem));
}

const part_kind_t ee24lc32_kind = {
	.name = "24lc32",
	.attach = PART_I2C,
	.options = "wp",
	.about = "a 4 KB EEPROM like a 24LC32A, 32-byte pages, 5 ms write cycle"
		 " (wp: WP high, writes ignored)",
	.addrs = { { 0xA0, 0xAE } },
	.size = sizeof(ee24lc32_t),
	.init = ee24lc32_part_init,
};
