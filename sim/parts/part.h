/*
 * part.h: a kind of part as data. Every part the simulator can put around
 * the boards has one descriptor (part_kind_t) in the registry (parts.c):
 * its name, where it attaches (the I2C bus, or a board's SPI chip select),
 * how it is made from its option's text, and the control requests it adds.
 * The world and the boards hold lists of the parts made (part_list_t).
 *
 * A new I2C part is one file (its model and its descriptor) and one line in
 * the registry; `--part KIND@ADDR[:OPTIONS]` then makes it and
 * `orfa-sim --help` lists it.
 *
 * Only forward declarations here, so a part's model builds on its own (the
 * SRF08's unit test) without simavr.
 */
#ifndef SIM_PARTS_PART_H
#define SIM_PARTS_PART_H

#include <stddef.h>
#include <stdint.h>

struct twi_bus_t;

/* Where a kind attaches. */
typedef enum part_attach_t {
	PART_I2C,		/* the world's I2C bus, at an 8-bit address */
	PART_SPI,		/* a board's SPI bus, at a chip-select pin */
} part_attach_t;

/* What a part is made with. */
typedef struct part_env_t {
	struct twi_bus_t *bus;		/* I2C: the bus (its `cycle` is the time) */
	uint32_t hz;			/* cycles per second */
	uint8_t addr8;			/* I2C: its 8-bit address */
	const uint32_t *adc_mv;		/* SPI: the board's 8 analog inputs, mV */
	const uint32_t *avcc;		/* SPI: the board's AVCC, mV */
	const char *opts;		/* the option text after KIND@ADDR: ("" for
					 * none; part_make lets only the kind's
					 * options word through) */
} part_env_t;

struct part_kind_t;

/* One part made: its kind and its context struct, whose first member is
 * the bus's view of it (twi_dev_t or spi_dev_t; what attaches the part
 * names that view after its kind and sets how it speaks SPI). */
typedef struct part_t {
	const struct part_kind_t *kind;
	void *self;
	uint8_t addr8;			/* I2C: the address it was made at */
} part_t;

#define PART_LIST_MAX 64

typedef struct part_list_t {
	part_t item[PART_LIST_MAX];
	int n;
} part_list_t;

/* A control request a kind adds: `NAME ARGS`. FN answers ARGV (ARGV[0]
 * is NAME) about the parts in LIST (of every kind: it picks its own) at
 * cycle NOW with one line in OUT: "OK", a state, or "ERR ...". */
typedef struct part_request_t {
	const char *name;
	const char *args;
	void (*fn)(const part_list_t *list, uint64_t now, int argc, char **argv,
		   char *out, size_t cap);
} part_request_t;

/* Even 8-bit addresses FIRST, FIRST + 2, .. LAST: where an I2C part can be. */
typedef struct part_addr_span_t {
	uint8_t first, last;
} part_addr_span_t;

#define PART_ADDR_SPANS 4

/* One quantity a part senses: N values, each within MIN..MAX (its units),
 * RANGE the same for errors ("+-16 g"), stored as N doubles at byte AT of
 * the part's context struct (offsetof). */
typedef struct part_sense_t {
	const char *quantity;
	int n;
	double min, max;
	const char *range;
	size_t at;
} part_sense_t;

typedef struct part_kind_t {
	const char *name;		/* KIND in the options: "eeprom24" */
	part_attach_t attach;
	const char *options;		/* the one option it takes, a flag word:
					 * "wp", or "" for none (part_make refuses
					 * any other); --help shows it */
	const char *about;		/* one line for --help */
	/* I2C: the addresses it can have, spans in the order --help names them
	 * (the unused ones 0; none: any even address); part_kind_addr_ok */
	part_addr_span_t addrs[PART_ADDR_SPANS];
	/* Its context struct: SIZE bytes, zeroed, then set up by INIT from
	 * ENV (its option already checked). */
	size_t size;
	void (*init)(void *self, const part_env_t *env);
	const part_request_t *requests;
	int nrequests;
	/* What it senses, set by the control request `sense @ADDR QUANTITY
	 * V...` (part_sense): QUANTITY ("accel", "gyro", "field", "temp",
	 * "pressure", "range", ...) with its N values in physical units (m/s^2,
	 * degrees/s, microtesla, degrees C, Pa, ...; part_sense_units).
	 * Either a table, SENSE_TABLE (NSENSE entries, WHO naming the part in
	 * errors: "an MPU-6050"), whose values part_sense checks and stores
	 * after BEFORE_SENSE (NULL: none) brought the part up to cycle NOW; or
	 * a function of its own, SENSE, with SENSES its quantities for --help
	 * ("temp, pressure"). Neither: it senses nothing. */
	const part_sense_t *sense_table;
	int nsense;
	const char *who;
	void (*before_sense)(void *self, uint64_t now);
	int (*sense)(void *self, uint64_t now, const char *quantity, const double *v, int n,
		     char *err, size_t cap);
	const char *senses;
} part_kind_t;

/* The quantities `sense` knows and their units, for help and errors:
 * "accel" -> "m/s^2", NULL for an unknown one. */
const char *part_sense_units(const char *quantity);

/* KIND's quantities for --help and errors, "accel, gyro, temp", or NULL
 * when it senses nothing. */
const char *part_kind_senses(const part_kind_t *kind, char *buf, size_t cap);

/* Tell the part SELF of KIND that it senses QUANTITY with its N values V
 * from cycle NOW. 0, or -1 with ERR (CAP bytes) saying why: a quantity the
 * part does not sense, the wrong number of values, a value outside the
 * part's range. */
int part_sense(const part_kind_t *kind, void *self, uint64_t now, const char *quantity,
	       const double *v, int n, char *err, size_t cap);

/* ADDR8 is one of KIND's addresses (any even one when it names none). */
int part_kind_addr_ok(const part_kind_t *kind, uint8_t addr8);

/* KIND's addresses for --help and errors ("0xE0, 0xE2 .. 0xFE"), or NULL
 * when it names none. */
const char *part_kind_addrs(const part_kind_t *kind, char *buf, size_t cap);

/* --- helpers for sensor parts ---------------------------------------------- */

/* VALUE times PER_UNIT, rounded to nearest, held within MIN..MAX: the raw
 * reading of a sensor with PER_UNIT LSB per unit that saturates there. */
int32_t part_raw(double value, double per_unit, int32_t min, int32_t max);

/* Cycles in US microseconds at HZ cycles per second, rounded up. */
uint64_t part_us(uint32_t hz, uint64_t us);

/* A measurement clock: event K (0, 1, ..) at cycle START + K x HZ / RATE,
 * RATE in millihertz, rounded up; at most LIMIT events (0: no limit). */
typedef struct part_ticker_t {
	uint64_t start;
	uint64_t mhz;			/* 0: stopped */
	uint64_t limit;
	uint64_t taken;			/* events counted by part_ticker_take */
} part_ticker_t;

/* Start T: the first event at cycle FIRST, then MHZ millihertz, at most LIMIT. */
void part_ticker_start(part_ticker_t *t, uint64_t first, uint64_t mhz, uint64_t limit);

/* No more events. */
void part_ticker_stop(part_ticker_t *t);

/* How many events came since the last call, up to and at cycle NOW. */
uint64_t part_ticker_take(part_ticker_t *t, uint32_t hz, uint64_t now);

/* The cycle of the next event not yet taken, UINT64_MAX when none comes. */
uint64_t part_ticker_next(const part_ticker_t *t, uint32_t hz);

/* The registry: every kind, NULL-terminated. */
extern const part_kind_t *const part_kinds[];

/* The kind called NAME that attaches to ATTACH, or NULL. */
const part_kind_t *part_kind_find(const char *name, part_attach_t attach);

/* The names of the kinds that attach to ATTACH, joined by SEP. */
const char *part_kind_names(part_attach_t attach, const char *sep, char *buf, size_t cap);

/* A new part of KIND (part_kind_t.init) made with ENV, or NULL with *ERR
 * saying why: "no options" when KIND takes none and ENV's opts is not "",
 * "bad option (wp)" when it is not KIND's options word either. */
void *part_make(const part_kind_t *kind, const part_env_t *env, const char **err);

/* Add a made part to LIST. 0, or -1 when full. */
int part_list_add(part_list_t *list, const part_kind_t *kind, void *self, uint8_t addr8);

/* The I2C part at ADDR8 in LIST, whatever its kind, or NULL. */
const part_t *part_list_at(const part_list_t *list, uint8_t addr8);

/* The part of KIND in LIST at ADDR8, or NULL. */
const part_t *part_list_find(const part_list_t *list, const part_kind_t *kind, uint8_t addr8);

#endif
