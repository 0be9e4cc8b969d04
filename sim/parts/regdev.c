/*
 * regdev.c: the I2C side of a register-addressed sensor part (regdev.h).
 */
#include "parts/regdev.h"

static int regdev_start(twi_dev_t *dev, uint8_t addr8)
{
	regdev_t *d = (regdev_t *)dev;

	d->selected = (addr8 & 0xfe) == d->addr8;
	d->want_ptr = d->selected && !(addr8 & 1);
	if (d->selected) {
		d->ops->catch_up(d, d->bus->cycle);
	}
	return d->selected;
}

static uint8_t regdev_next(const regdev_t *d, uint8_t reg)
{
	return d->ops->next ? d->ops->next(reg) : (uint8_t)(reg + 1);
}

static int regdev_write(twi_dev_t *dev, uint8_t byte)
{
	regdev_t *d = (regdev_t *)dev;

	if (!d->selected) {
		return 0;
	}
	if (d->want_ptr) {
		d->want_ptr = 0;
		d->ptr = byte & d->ops->ptr_mask;
		return 1;
	}
	d->ops->write(d, d->ptr, byte);
	if (d->ops->pairs) {
		d->want_ptr = 1;	/* the next byte is a register address again */
	} else {
		d->ptr = regdev_next(d, d->ptr);
	}
	return 1;
}

static uint8_t regdev_read(twi_dev_t *dev)
{
	regdev_t *d = (regdev_t *)dev;
	uint8_t v;

	if (!d->selected) {
		return 0xff;
	}
	v = d->ops->read(d, d->ptr);
	d->ptr = regdev_next(d, d->ptr);
	return v;
}

static void regdev_stop(twi_dev_t *dev)
{
	regdev_t *d = (regdev_t *)dev;

	d->selected = 0;
	d->want_ptr = 0;
}

static const twi_dev_ops_t regdev_twi_ops = {
	.start = regdev_start,
	.write = regdev_write,
	.read = regdev_read,
	.stop = regdev_stop,
};

void regdev_catch_up(void *self, uint64_t now)
{
	regdev_t *d = self;

	d->ops->catch_up(d, now);
}

void regdev_init(regdev_t *d, const part_env_t *env, const regdev_ops_t *ops)
{
	d->dev.ops = &regdev_twi_ops;
	d->ops = ops;
	d->bus = env->bus;
	d->hz = env->hz;
	d->addr8 = env->addr8 & 0xfe;
}
