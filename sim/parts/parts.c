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

void *part_make(const part_kind_t *kind, const part_env_t *env, const char **err)
{
	static char bad[64];
	void *self;

	if (*env->opts && strcmp(env->opts, kind->options) != 0) {
		if (!*kind->options) {
			*err = "no options";
		} else {
			snprintf(bad, sizeof(bad), "bad option (%s)", kind->options);
			*err = bad;
		}
		return NULL;
	}
	self = calloc(1, kind->size);
	if (!self) {
		*err = "out of memory";
		return NULL;
	}
	kind->init(self, env);
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

int part_kind_addr_ok(const part_kind_t *kind, uint8_t addr8)
{
	const part_addr_span_t *a = kind->addrs;

	if (!a[0].first) {
		return !(addr8 & 1);
	}
	for (int i = 0; i < PART_ADDR_SPANS && a[i].first; i++) {
		if (addr8 >= a[i].first && addr8 <= a[i].last && !((addr8 - a[i].first) & 1)) {
			return 1;
		}
	}
	return 0;
}

const char *part_kind_addrs(const part_kind_t *kind, char *buf, size_t cap)
{
	const part_addr_span_t *a = kind->addrs;
	size_t len = 0;

	if (!a[0].first) {
		return NULL;
	}
	buf[0] = 0;
	for (int i = 0; i < PART_ADDR_SPANS && a[i].first && len < cap; i++) {
		len += (size_t)snprintf(buf + len, cap - len, "%s0x%02X", i ? ", " : "",
					a[i].first);
		if (a[i].last != a[i].first && len < cap) {
			len += (size_t)snprintf(buf + len, cap - len, " .. 0x%02X", a[i].last);
		}
	}
	return buf;
}

const char *part_kind_senses(const part_kind_t *kind, char *buf, size_t cap)
{
	size_t len = 0;

	if (!kind->sense_table) {
		return kind->sense ? kind->senses : NULL;
	}
	buf[0] = 0;
	for (int i = 0; i < kind->nsense && len < cap; i++) {
		len += (size_t)snprintf(buf + len, cap - len, "%s%s", i ? ", " : "",
					kind->sense_table[i].quantity);
	}
	return buf;
}

/* The entry of KIND's table that QUANTITY with its N values V fits: its
 * index, or -1 with ERR (CAP bytes) saying why. */
static int part_sense_pick(const part_kind_t *kind, const char *quantity, const double *v, int n,
			   char *err, size_t cap)
{
	const char *who = kind->who;
	const part_sense_t *table = kind->sense_table;
	int count = kind->nsense;
	char names[80];

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
	snprintf(err, cap, "%s does not sense %s; it senses %s", who, quantity,
		 part_kind_senses(kind, names, sizeof(names)));
	return -1;
}

int part_sense(const part_kind_t *kind, void *self, uint64_t now, const char *quantity,
	       const double *v, int n, char *err, size_t cap)
{
	int i;

	if (!kind->sense_table) {
		return kind->sense(self, now, quantity, v, n, err, cap);
	}
	i = part_sense_pick(kind, quantity, v, n, err, cap);
	if (i < 0) {
		return -1;
	}
	if (kind->before_sense) {
		kind->before_sense(self, now);	/* what came before NOW saw the old values */
	}
	memcpy((char *)self + kind->sense_table[i].at, v, (size_t)n * sizeof(*v));
	return 0;
}

/* --- helpers for sensor parts ---------------------------------------------- */

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
