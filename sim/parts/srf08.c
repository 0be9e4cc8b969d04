/*
 * srf08.c: Devantech SRF08 range finder device (see srf08.h).
 *
 * Facts from the technical specification, in its order:
 *  - addressed like a 24xx EEPROM: a location byte, then data; the
 *    location counter moves on after every byte read or written;
 *  - shipped at 0xE0, settable to the 16 even addresses E0..FE; every
 *    SRF08 also answers the general broadcast address 0 (for starting all
 *    of them at once; results are read from each real address);
 *  - location 0 written: the command register; read: software revision;
 *    location 1 written: max gain (power-up 31), read: light sensor;
 *    location 2 written: range register (power-up 255), read with 3: first
 *    echo, high byte first; 4,5 the second .. 34,35 the 17th; only 0, 1
 *    and 2 can be written;
 *  - commands 0x50/0x51/0x52 range with the result in inches/cm/us of
 *    flight; 0x53/0x54/0x55 the same in ANN mode; A0, AA, A5 then the new
 *    address, each in its own write to location 0 and nothing else in
 *    between, change the address;
 *  - a value 0 means no echo, and no later location holds one either; the
 *    echo buffer is cleared when a ranging starts; echoes nearest first;
 *  - ranging lasts 65 ms by default, less with a smaller range register;
 *    the maximum range is (range register + 1) x 43 mm (24 -> 1 m, 140 ->
 *    6 m, 255 -> 11008 mm);
 *  - while ranging it does not respond to the bus at all: a master that
 *    reads anyway sees 255, SDA being pulled up with nobody driving it
 *    (here: the address is not acknowledged, the bus answers FF);
 *  - the light sensor is converted once per ranging, just before the ping;
 *    location 1 shows it once the ranging is done;
 *  - ANN mode: locations 4..35 are 32 slots of 2048 us of flight (about
 *    352 mm each), non-zero where an echo came back; 2,3 as in ranging.
 *
 * Assumptions where the document is silent (docs/simulator.md repeats them):
 *  - speed of sound 343.75 m/s, the one behind the ANN slots (2048 us of
 *    round trip per 352 mm): flight us = 64 x mm / 11; cm and inches are
 *    the distance itself, rounded to nearest;
 *  - ranging time in proportion to the range: 65 ms x (range + 1) / 256
 *    (65 ms at 255, 6.35 ms at 24: the flight time of the maximum range at
 *    343.75 m/s is 64.0 ms and 6.25 ms);
 *  - what is in front is sampled at the ping; the gain register is kept but
 *    changes nothing (targets are ideal reflectors);
 *  - writes to locations 3 and up are acknowledged and ignored, reads past
 *    35 give 0; unknown commands are ignored; a fourth address-sequence
 *    byte that is not one of E0..FE ends the sequence and counts as an
 *    ordinary command; the light reading is 0 before the first ranging.
 */
#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "parts/part.h"
#include "parts/srf08.h"

extern const part_kind_t srf08_kind;

#define SRF08_STEP_MM 43u
#define SRF08_ANN_SLOTS 32
#define SRF08_ANN_SLOT_MM 352u
#define SRF08_FULL_MS 65u

uint32_t srf08_max_mm(uint8_t range)
{
	return ((uint32_t)range + 1) * SRF08_STEP_MM;
}

uint64_t srf08_ranging_cycles(const srf08_t *s, uint8_t range)
{
	/* 65 ms for the 256 steps of 255, that share for fewer */
	return (uint64_t)s->hz * SRF08_FULL_MS * ((uint64_t)range + 1) / (1000u * 256u);
}

uint16_t srf08_convert(uint8_t cmd, uint32_t mm)
{
	uint64_t v;

	/* 0x50 and 0x53 inches, 0x51 and 0x54 cm, 0x52 and 0x55 us */
	switch ((cmd - 0x50) % 3) {
	case 0:		/* inches: 25.4 mm */
		v = ((uint64_t)mm * 10 + 127) / 254;
		break;
	case 1:		/* centimetres */
		v = ((uint64_t)mm + 5) / 10;
		break;
	default:	/* round trip at 11/32 mm per us */
		v = ((uint64_t)mm * 128 + 11) / 22;
		break;
	}
	return v > 0xffff ? 0xffff : (uint16_t)v;
}

int srf08_busy(const srf08_t *s, uint64_t now)
{
	return now < s->busy_until;
}

/* The echoes a ping sees with the current range register: distances,
 * nearest first, those beyond the range dropped. Returns how many. */
static int srf08_echoes(const srf08_t *s, uint32_t *mm)
{
	uint32_t max = srf08_max_mm(s->range);
	int n = 0;

	for (int i = 0; i < SRF08_TARGETS; i++) {
		uint32_t d = s->target_mm[i];

		if (d == 0 || d > max || (n == 1 && mm[0] == d)) {
			continue;	/* nothing there, too far, or the same wall */
		}
		if (n == 1 && d < mm[0]) {
			mm[1] = mm[0];
			mm[0] = d;
		} else {
			mm[n] = d;
		}
		n++;
	}
	return n;
}

static void srf08_range_start(srf08_t *s, uint8_t cmd)
{
	uint32_t mm[SRF08_TARGETS];
	int n = srf08_echoes(s, mm);
	int ann = cmd >= 0x53;

	memset(s->loc, 0, sizeof(s->loc));
	s->light_reading = s->light;
	for (int i = 0; i < n && (!ann || i == 0); i++) {
		uint16_t v = srf08_convert(cmd, mm[i]);

		s->loc[2 + 2 * i] = (uint8_t)(v >> 8);
		s->loc[3 + 2 * i] = (uint8_t)v;
	}
	if (ann) {
		/* locations 4..35 are time slots instead of further echoes */
		for (int i = 0; i < n; i++) {
			uint32_t slot = mm[i] / SRF08_ANN_SLOT_MM;

			if (slot < SRF08_ANN_SLOTS) {
				s->loc[4 + slot] = 1;
			}
		}
	}
	s->busy_until = s->bus->cycle + srf08_ranging_cycles(s, s->range);
	s->rangings++;
}

static int srf08_valid_addr(uint8_t a)
{
	return a >= 0xE0 && !(a & 1);
}

/* A byte written to location 0. */
static void srf08_command(srf08_t *s, uint8_t cmd)
{
	static const uint8_t seq[3] = { 0xA0, 0xAA, 0xA5 };

	if (s->addr_seq == 3) {
		s->addr_seq = 0;
		if (srf08_valid_addr(cmd)) {
			s->addr8 = cmd;
			return;
		}
	}
	if (cmd == seq[0]) {
		s->addr_seq = 1;	/* a new sequence may start any time */
		return;
	}
	if (s->addr_seq && cmd == seq[s->addr_seq]) {
		s->addr_seq++;
		return;
	}
	/* anything else in the middle breaks the sequence */
	s->addr_seq = 0;
	if (cmd >= 0x50 && cmd <= 0x55) {
		srf08_range_start(s, cmd);
	}
}

static int srf08_start(twi_dev_t *dev, uint8_t addr8)
{
	srf08_t *s = (srf08_t *)dev;
	int write = !(addr8 & 1);

	s->selected = 0;
	s->want_ptr = 0;
	if (srf08_busy(s, s->bus->cycle)) {
		return 0;	/* deaf while ranging */
	}
	/* its own address either way; the broadcast address 0 to write */
	if ((addr8 & 0xfe) == s->addr8 || addr8 == 0x00) {
		s->selected = 1;
		s->want_ptr = (uint8_t)write;
	}
	return s->selected;
}

static int srf08_write(twi_dev_t *dev, uint8_t byte)
{
	srf08_t *s = (srf08_t *)dev;

	if (!s->selected || srf08_busy(s, s->bus->cycle)) {
		return 0;	/* a command in this transfer started a ranging */
	}
	if (s->want_ptr) {
		s->want_ptr = 0;
		s->ptr = byte;
		return 1;
	}
	switch (s->ptr) {
	case 0:
		srf08_command(s, byte);
		break;
	case 1:
		s->gain = byte;
		break;
	case 2:
		s->range = byte;
		break;
	default:
		break;		/* read-only locations */
	}
	s->ptr++;		/* uint8_t: wraps at 256 */
	return 1;
}

static uint8_t srf08_read(twi_dev_t *dev)
{
	srf08_t *s = (srf08_t *)dev;
	uint8_t v;

	if (!s->selected || srf08_busy(s, s->bus->cycle)) {
		return 0xff;	/* SDA left to the pull-up */
	}
	if (s->ptr == 0) {
		v = SRF08_REVISION;
	} else if (s->ptr == 1) {
		v = s->light_reading;
	} else if (s->ptr < SRF08_LOCATIONS) {
		v = s->loc[s->ptr];
	} else {
		v = 0;
	}
	s->ptr++;
	return v;
}

static void srf08_stop(twi_dev_t *dev)
{
	srf08_t *s = (srf08_t *)dev;

	s->selected = 0;
	s->want_ptr = 0;
}

static const twi_dev_ops_t srf08_ops = {
	.start = srf08_start,
	.write = srf08_write,
	.read = srf08_read,
	.stop = srf08_stop,
};

void srf08_init(srf08_t *s, uint8_t addr8, uint32_t hz, const twi_bus_t *bus)
{
	memset(s, 0, sizeof(*s));
	s->dev.ops = &srf08_ops;
	s->dev.name = "srf08";
	s->bus = bus;
	s->hz = hz;
	s->addr8 = addr8 & 0xfe;
	s->gain = SRF08_GAIN_DEFAULT;
	s->range = SRF08_RANGE_DEFAULT;
}

void srf08_set_targets(srf08_t *s, uint32_t mm, uint32_t mm2)
{
	s->target_mm[0] = mm;
	s->target_mm[1] = mm2;
}

void srf08_set_light(srf08_t *s, uint8_t level)
{
	s->light = level;
}

/* --- the control request `srf08`: what each SRF08 senses, its state ------- */

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
static srf08_t *srf08_find(const part_list_t *list, const char *s)
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
	for (int i = 0; i < list->n; i++) {
		srf08_t *d = list->item[i].self;

		if (list->item[i].kind == &srf08_kind && d->addr8 == v) {
			return d;
		}
	}
	return NULL;
}

static void srf08_control(const part_list_t *list, uint64_t now, int argc, char **argv,
			  char *out, size_t cap)
{
	srf08_t *s;
	uint32_t mm = 0, mm2 = 0, level;

	if (argc < 2 || argc > 5) {
		snprintf(out, cap, "ERR %s", SRF08_CTL_USAGE);
		return;
	}
	s = srf08_find(list, argv[1]);
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

/* --- descriptor ------------------------------------------------------------ */

static void srf08_part_init(void *self, const part_env_t *env)
{
	srf08_init(self, env->addr8, env->hz, env->bus);
}

/* `sense @E0 range MM [MM2]` (millimetres, 0: nothing there), `sense @E0
 * light N` (0..255): the same as the `srf08` request's. */
static int srf08_sense(void *self, uint64_t now, const char *quantity, const double *v, int n,
		       char *err, size_t cap)
{
	srf08_t *s = self;

	(void)now;
	if (!strcmp(quantity, "range") && (n == 1 || n == 2)) {
		for (int i = 0; i < n; i++) {
			if (v[i] < 0 || v[i] > SRF08_CTL_MAX_MM) {
				snprintf(err, cap, "range MM [MM2]: 0..%u mm (0: nothing there)",
					 SRF08_CTL_MAX_MM);
				return -1;
			}
		}
		srf08_set_targets(s, (uint32_t)(v[0] + 0.5), n == 2 ? (uint32_t)(v[1] + 0.5) : 0);
		return 0;
	}
	if (!strcmp(quantity, "light") && n == 1) {
		if (v[0] < 0 || v[0] > 255) {
			snprintf(err, cap, "light N: 0..255");
			return -1;
		}
		srf08_set_light(s, (uint8_t)(v[0] + 0.5));
		return 0;
	}
	snprintf(err, cap, "an SRF08 senses range MM [MM2] and light N, not %s with %d value%s",
		 quantity, n, n == 1 ? "" : "s");
	return -1;
}

static const part_request_t srf08_requests[] = {
	{ "srf08", "ADDR [range MM [MM2] | light N]", srf08_control },
};

const part_kind_t srf08_kind = {
	.name = "srf08",
	.attach = PART_I2C,
	.options = "",
	.about = "a Devantech SRF08 ultrasonic range finder (request srf08)",
	/* the 16 addresses it can be set to, the one it ships with first */
	.addrs = { { 0xE0, 0xE0 }, { 0xE2, 0xFE } },
	.size = sizeof(srf08_t),
	.init = srf08_part_init,
	.requests = srf08_requests,
	.nrequests = 1,
	.sense = srf08_sense,
	.senses = "range, light",
};
