/*
 * parts.c: the registry of part kinds (part.h). A new kind is one line here.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "parts/part.h"

extern const part_kind_t eeprom24_kind, srf08_kind, eeprom25_kind, mcp3008_kind;
extern const part_kind_t mpu6050_kind, hmc5883l_kind, lis3mdl_kind;
extern const part_kind_t bmp280_kind;
extern const part_kind_t ee24lc32_kind;

const part_kind_t *const part_kinds[] = {
	&eeprom24_kind,
	&srf08_kind,
	&mpu6050_kind,
	&hmc5883l_kind,
	&lis3mdl_kind,
	&bmp280_kind,
	&ee24lc32_kind,
	&eeprom25_kind,
	&mcp3008_kind,
	NULL,
};

const part_kind_t *part_kind_find(const char *name, part_attach_t attach)
{
	for (int i = 0; part_kinds[i]; i++) {
		if (part_kinds[i]->attach == attach && strcmp(part_kinds[i]->name, name) == 0) {
			return part_kinds[i];
		}
	}
	return NULL;
}

const char *part_kind_names(part_attach_t attach, const char *sep, char *buf, size_t cap)
{
	size_t n = 0;

	buf[0] = 0;
	for (int i = 0; part_kinds[i]; i++) {
		const char *name = part_kinds[i]->name;

		if (part_kinds[i]->attach != attach ||
		    n + strlen(sep) + strlen(name) + 1 > cap) {
			continue;
		}
		if (n) {
			strcpy(buf + n, sep);
			n += strlen(sep);
		}
		strcpy(buf + n, name);
		n += strlen(name);
	}
	return buf;
}

void *part_make(const part_kind_t *kind, const part_env_t *env, const char *opts,
		const char **err)
{
	void *self = calloc(1, kind->size);

	if (!self) {
		*err = "out of memory";
		return NULL;
	}
	if (kind->init(self, env, opts, err) < 0) {
		free(self);
		return NULL;
	}
	return self;
}

int part_list_add(part_list_t *list, const part_kind_t *kind, void *self, uint8_t addr8)
{
	if (list->n == PART_LIST_MAX) {
		return -1;
	}
	list->item[list->n++] = (part_t) { .kind = kind, .self = self, .addr8 = addr8 };
	return 0;
}

const part_t *part_list_at(const part_list_t *list, uint8_t addr8)
{
	for (int i = 0; i < list->n; i++) {
		if (list->item[i].kind->attach == PART_I2C && list->item[i].addr8 == addr8) {
			return &list->item[i];
		}
	}
	return NULL;
}

const char *part_sense_units(const char *quantity)
{
	static const char *const units[][2] = {
		{ "accel", "m/s^2" }, { "gyro", "degrees/s" }, { "field", "microtesla" },
		{ "temp", "degrees C" }, { "pressure", "Pa" }, { "range", "mm" },
		{ "light", "0..255" },
	};

	for (size_t i = 0; i < sizeof(units) / sizeof(units[0]); i++) {
		if (strcmp(units[i][0], quantity) == 0) {
			return units[i][1];
		}
	}
	return NULL;
}

const part_t *part_list_find(const part_list_t *list, const part_kind_t *kind, uint8_t addr8)
{
	for (int i = 0; i < list->n; i++) {
		if (list->item[i].kind == kind && list->item[i].addr8 == addr8) {
			return &list->item[i];
		}
	}
	return NULL;
}

/* --- helpers for sensor parts ---------------------------------------------- */

int part_sense_pick(const char *who, const part_sense_t *table, int count, const char *quantity,
		    const double *v, int n, char *err, size_t cap)
{
	for (int i = 0; i < count; i++) {
		const part_sense_t *s = &table[i];

		if (strcmp(s->quantity, quantity) != 0) {
			continue;
		}
		if (n != s->n) {
			snprintf(err, cap, "%s takes %d value%s, not %d", quantity, s->n,
				 s->n == 1 ? "" : "s", n);
			return -1;
		}
		for (int k = 0; k < n; k++) {
			if (v[k] < s->min || v[k] > s->max) {
				snprintf(err, cap, "%s %g is outside %s's range %g..%g %s (%s)",
					 quantity, v[k], who, s->min, s->max,
					 part_sense_units(quantity), s->range);
				return -1;
			}
		}
		return i;
	}
	{
		size_t len = (size_t)snprintf(err, cap, "%s does not sense %s; it senses", who,
					      quantity);

		for (int i = 0; i < count && len < cap; i++) {
			len += (size_t)snprintf(err + len, cap - len, "%s %s", i ? "," : "",
						table[i].quantity);
		}
	}
	return -1;
}

int32_t part_raw(double value, double per_unit, int32_t min, int32_t max)
{
	double raw = floor(value * per_unit + 0.5);

	if (raw < min) {
		return min;
	}
	if (raw > max) {
		return max;
	}
	return (int32_t)raw;
}

uint64_t part_us(uint32_t hz, uint64_t us)
{
	return ((uint64_t)hz * us + 999999) / 1000000;
}

/* Cycles from START to event K, rounded up. */
static uint64_t part_ticker_at(const part_ticker_t *t, uint32_t hz, uint64_t k)
{
	unsigned __int128 c = (unsigned __int128)k * hz * 1000u;

	return t->start + (uint64_t)((c + t->mhz - 1) / t->mhz);
}

void part_ticker_start(part_ticker_t *t, uint64_t first, uint64_t mhz, uint64_t limit)
{
	*t = (part_ticker_t) { .start = first, .mhz = mhz, .limit = limit };
}

void part_ticker_stop(part_ticker_t *t)
{
	t->mhz = 0;
}

uint64_t part_ticker_take(part_ticker_t *t, uint32_t hz, uint64_t now)
{
	uint64_t total, fresh;

	if (!t->mhz || now < t->start) {
		return 0;
	}
	total = (uint64_t)((unsigned __int128)(now - t->start) * t->mhz / ((uint64_t)hz * 1000u)) + 1;
	if (t->limit && total > t->limit) {
		total = t->limit;
	}
	fresh = total > t->taken ? total - t->taken : 0;
	t->taken = total > t->taken ? total : t->taken;
	return fresh;
}

uint64_t part_ticker_next(const part_ticker_t *t, uint32_t hz)
{
	if (!t->mhz || (t->limit && t->taken >= t->limit)) {
		return UINT64_MAX;
	}
	return part_ticker_at(t, hz, t->taken);
}
