/*
 * srf08.h: a Devantech SRF08 ultrasonic range finder on the simulated I2C
 * bus, after Devantech's "SRF08 Ultra sonic range finder - Technical
 * Specification" (robot-electronics.co.uk, srf08tech; docs/simulator.md
 * lists what is modelled and what is assumed where the document is silent).
 *
 * What the part senses is set from outside (control request `srf08`): the
 * distance to the nearest target, optionally a second, farther one, and the
 * light level. A ranging command starts a measurement that takes simulated
 * time (read from the bus's `cycle`); meanwhile the part ignores the bus.
 */
#ifndef SIM_PARTS_SRF08_H
#define SIM_PARTS_SRF08_H

#include <stdint.h>

#include "periph/twi_bus.h"

#define SRF08_ADDR_DEFAULT 0xE0	/* as shipped */
#define SRF08_LOCATIONS 36	/* 0..35: command/revision .. 17th echo */
#define SRF08_ECHOES 17		/* locations 2,3 .. 34,35 */
#define SRF08_TARGETS 2		/* what the simulation lets one place */
#define SRF08_GAIN_DEFAULT 31
#define SRF08_RANGE_DEFAULT 255
/* The document names no revision number; anything but 0xFF serves the
 * "poll location 0 until it is not 255" idiom. */
#define SRF08_REVISION 0x0A

typedef struct srf08_t {
	twi_dev_t dev;			/* first: the bus's view */
	const twi_bus_t *bus;		/* its `cycle` is the time of an event */
	uint32_t hz;			/* bus cycles per second */
	uint8_t addr8;			/* 8-bit address, R/W bit clear */
	uint8_t ptr;			/* location counter */
	uint8_t selected;		/* addressed since the last START */
	uint8_t want_ptr;		/* next written byte is the location */
	uint8_t addr_seq;		/* A0, AA, A5 seen in order: 0..3 */
	uint8_t gain;			/* location 1, written */
	uint8_t range;			/* location 2, written */
	uint8_t light_reading;		/* location 1, read */
	uint8_t loc[SRF08_LOCATIONS];	/* results: locations 2..35 */
	uint64_t busy_until;		/* ranging until this cycle */
	uint32_t rangings;		/* completed or running, for status */
	/* the world the part senses */
	uint32_t target_mm[SRF08_TARGETS];	/* 0: nothing there */
	uint8_t light;
} srf08_t;

/* Power-up state at ADDR8 (one of E0, E2, .. FE), on BUS (for the time of
 * each event), whose cycles run at HZ per second. Attach &s->dev to BUS. */
void srf08_init(srf08_t *s, uint8_t addr8, uint32_t hz, const twi_bus_t *bus);

/* What is in front of it: distances in mm, 0 for none (MM2: a second
 * echo; echoes are reported nearest first). Read at the next ping. */
void srf08_set_targets(srf08_t *s, uint32_t mm, uint32_t mm2);

/* Ambient light as the on-board sensor converts it, 0..255 (brighter is
 * more); sampled at the start of the next ranging. */
void srf08_set_light(srf08_t *s, uint8_t level);

/* Still ranging at bus cycle NOW (deaf to the bus). */
int srf08_busy(const srf08_t *s, uint64_t now);

/* Cycles a ranging takes with range register RANGE. */
uint64_t srf08_ranging_cycles(const srf08_t *s, uint8_t range);

/* Largest detected distance in mm with range register RANGE. */
uint32_t srf08_max_mm(uint8_t range);

/* A distance in the unit of ranging command CMD (0x50..0x55: inches, cm,
 * microseconds of flight, then the same for ANN mode), rounded to
 * nearest, capped at 65535. */
uint16_t srf08_convert(uint8_t cmd, uint32_t mm);

#endif
