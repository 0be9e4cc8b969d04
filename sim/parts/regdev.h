/*
 * regdev.h: the I2C side of a register-addressed sensor part. The first
 * byte of a write transfer sets the register pointer; each further byte
 * written or read goes to the part's register callbacks and moves the
 * pointer on by the part's rule (or, with `pairs`, a write alternates
 * register and value and does not move on); the pointer stays across STOP and repeated
 * START. When the part is addressed (a transfer begins) it is told to catch
 * up with its measurements, so the registers change only between transfers.
 */
#ifndef SIM_PARTS_REGDEV_H
#define SIM_PARTS_REGDEV_H

#include <stdint.h>

#include "parts/part.h"
#include "periph/twi_bus.h"

typedef struct regdev_t regdev_t;

typedef struct regdev_ops_t {
	/* Measurements due up to cycle NOW into the registers. */
	void (*catch_up)(regdev_t *d, uint64_t now);
	uint8_t (*read)(regdev_t *d, uint8_t reg);
	void (*write)(regdev_t *d, uint8_t reg, uint8_t v);
	/* The pointer after an access to REG (NULL: REG + 1, 8 bits). */
	uint8_t (*next)(uint8_t reg);
	uint8_t ptr_mask;		/* bits of the written pointer kept */
	uint8_t pairs;			/* writes are register/value pairs (the BMP280) */
} regdev_ops_t;

struct regdev_t {
	twi_dev_t dev;			/* first: the bus's view */
	const regdev_ops_t *ops;
	const twi_bus_t *bus;		/* its `cycle` is the time of an event */
	uint32_t hz;
	uint8_t addr8;
	uint8_t ptr;
	uint8_t selected, want_ptr;
};

/* Bring the part SELF (whose first member is its regdev_t) up to cycle
 * NOW: its catch_up; a sensor part's part_kind_t.before_sense. */
void regdev_catch_up(void *self, uint64_t now);

/* Set up D (the first member of the part's context) at ENV's address. */
void regdev_init(regdev_t *d, const part_env_t *env, const regdev_ops_t *ops);

#endif
