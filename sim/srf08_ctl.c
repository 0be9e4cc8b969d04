/*
 * srf08_ctl.c: the control request `srf08`: set what each simulated SRF08
 * senses, or show its state.
 */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <strings.h>

#include "srf08_ctl.h"

#define SRF08_CTL_MAX_MM 100000u	/* 100 m: far beyond any range */
#define SRF08_CTL_USAGE "srf08 ADDR [range MM [MM2] | light N]"

/* Decimal 0..MAX. 0 or -1. */
static int srf08_parse_dec(const char *s, uint32_t max, uint32_t *out)
{
	char *end;
	unsigned long v;

	if (!*s || *s == '-' || *s == '+') {
		return -1;
	}
	errno = 0;
	v = strtoul(s, &end, 10);
	if (errno || *end || v > max) {
		return -1;
	}
	*out = (uint32_t)v;
	return 0;
}

/* The device answering at the 8-bit address in S ("E0" or "0xE0"), as the
 * firmware sees it now (after an address change: the new one). */
static srf08_t *srf08_find(srf08_t *devs, int n, const char *s)
{
	char *end;
	unsigned long v;

	if (!*s || *s == '-' || *s == '+') {
		return NULL;
	}
	v = strtoul(s, &end, 16);
	if (*end || v > 0xff) {
		return NULL;
	}
	for (int i = 0; i < n; i++) {
		if (devs[i].addr8 == v) {
			return &devs[i];
		}
	}
	return NULL;
}

void srf08_control(srf08_t *devs, int n, uint64_t now, int argc, char **argv,
		   char *out, size_t cap)
{
	srf08_t *s;
	uint32_t mm = 0, mm2 = 0, level;

	if (argc < 2 || argc > 5) {
		snprintf(out, cap, "ERR %s", SRF08_CTL_USAGE);
		return;
	}
	s = srf08_find(devs, n, argv[1]);
	if (!s) {
		snprintf(out, cap, "ERR no SRF08 at '%s' (give its 8-bit address in hex, E0)",
			 argv[1]);
		return;
	}
	if (argc == 2) {
		snprintf(out, cap, "addr %02X range %" PRIu32 " %" PRIu32 " light %u"
			 " gain %u rangereg %u busy %d rangings %" PRIu32,
			 s->addr8, s->target_mm[0], s->target_mm[1], s->light, s->gain,
			 s->range, srf08_busy(s, now), s->rangings);
	} else if (!strcasecmp(argv[2], "range") && (argc == 4 || argc == 5)) {
		if (srf08_parse_dec(argv[3], SRF08_CTL_MAX_MM, &mm) < 0 ||
		    (argc == 5 && srf08_parse_dec(argv[4], SRF08_CTL_MAX_MM, &mm2) < 0)) {
			snprintf(out, cap, "ERR srf08 ADDR range MM [MM2]: millimetres 0..%u,"
				 " decimal (0: nothing there)", SRF08_CTL_MAX_MM);
			return;
		}
		srf08_set_targets(s, mm, mm2);
		snprintf(out, cap, "OK");
	} else if (!strcasecmp(argv[2], "light") && argc == 4) {
		if (srf08_parse_dec(argv[3], 255, &level) < 0) {
			snprintf(out, cap, "ERR srf08 ADDR light N: N 0..255, decimal");
			return;
		}
		srf08_set_light(s, (uint8_t)level);
		snprintf(out, cap, "OK");
	} else {
		snprintf(out, cap, "ERR %s", SRF08_CTL_USAGE);
	}
}
