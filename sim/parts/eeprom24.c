/*
 * eeprom24.c: 24C02-like EEPROM device.
 */
#include <string.h>

#include "parts/eeprom24.h"
#include "parts/part.h"

static int eeprom24_start(twi_dev_t *dev, uint8_t addr8)
{
	eeprom24_t *e = (eeprom24_t *)dev;

	e->selected = (addr8 & 0xfe) == e->addr8;
	e->want_word_addr = e->selected && !(addr8 & 1);
	return e->selected;
}

static int eeprom24_write(twi_dev_t *dev, uint8_t byte)
{
	eeprom24_t *e = (eeprom24_t *)dev;

	if (!e->selected) {
		return 0;
	}
	if (e->want_word_addr) {
		e->want_word_addr = 0;
		e->ptr = byte;
		return 1;
	}
	if (e->write_protect) {
		return 0;	/* like the AT24C parts with WP high: data NACKed */
	}
	e->mem[e->ptr] = byte;
	/* The counter's low bits roll over inside the page while writing. */
	e->ptr = (uint8_t)((e->ptr & ~(EEPROM24_PAGE - 1)) |
			   ((e->ptr + 1) & (EEPROM24_PAGE - 1)));
	return 1;
}

static uint8_t eeprom24_read(twi_dev_t *dev)
{
	eeprom24_t *e = (eeprom24_t *)dev;
	uint8_t v = e->mem[e->ptr];

	e->ptr++;		/* uint8_t: wraps at 256 */
	return v;
}

static void eeprom24_stop(twi_dev_t *dev)
{
	eeprom24_t *e = (eeprom24_t *)dev;

	e->selected = 0;
	e->want_word_addr = 0;
}

static const twi_dev_ops_t eeprom24_ops = {
	.start = eeprom24_start,
	.write = eeprom24_write,
	.read = eeprom24_read,
	.stop = eeprom24_stop,
};

/* --- descriptor ------------------------------------------------------------ */

/* Erased (FF), at ENV's address; option wp: WP high. */
static void eeprom24_init(void *self, const part_env_t *env)
{
	eeprom24_t *e = self;

	memset(e->mem, 0xff, sizeof(e->mem));
	e->dev.ops = &eeprom24_ops;
	e->addr8 = env->addr8 & 0xfe;
	e->write_protect = !strcmp(env->opts, "wp");
}

const part_kind_t eeprom24_kind = {
	.name = "eeprom24",
	.attach = PART_I2C,
	.options = "wp",
	.about = "a 256-byte EEPROM like a 24C02 (wp: its WP pin high, data NACKed)",
	.size = sizeof(eeprom24_t),
	.init = eeprom24_init,
};
