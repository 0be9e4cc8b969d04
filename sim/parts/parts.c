/*
 * parts.c: the registry of part kinds (part.h). A new kind is one line here.
 */
#include <stdlib.h>
#include <string.h>

#include "parts/part.h"

extern const part_kind_t eeprom24_kind, srf08_kind, eeprom25_kind, mcp3008_kind;
extern const part_kind_t bmp280_kind;
extern const part_kind_t ee24lc32_kind;

const part_kind_t *const part_kinds[] = {
	&eeprom24_kind,
	&srf08_kind,
	&eeprom25_kind,
	&mcp3008_kind,
	&bmp280_kind,
	&ee24lc32_kind,
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
