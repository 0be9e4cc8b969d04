/*
 * main.c: orfa-sim, an ORFA board under simavr 1.6 (docs/simulator.md).
 *
 * Single-threaded: the world (world.h: the boards in lock-step, the bus)
 * runs in batches of about a millisecond of simulated time; between batches
 * the pty is serviced, the idle throttle decides whether to wait for wall
 * time, and signals are noticed. The pty is never serviced from cycle
 * timers because a watchdog reset wipes them.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>

#include "sim_avr.h"

#include "boards/sim_boards.h"
#include "firmware/i2c_addr.h"
#include "harness/control.h"
#include "periph/pty.h"
#include "boards/sim_board.h"
#include "harness/trace.h"
#include "harness/world.h"
#include "parts/part.h"

#define SIM_BATCH_CYCLES (SIM_FREQUENCY / 1000)	/* 1 ms simulated */
#define SIM_IDLE_AFTER_S 0.5
/* --real-time: further behind wall time than this, it starts again from now. */
#define SIM_REAL_TIME_BEHIND_S 0.002
#define SIM_BOOT_MAX_CYCLES (SIM_FREQUENCY / 10)	/* 100 ms simulated */
#define SIM_UCSRB_RXEN 0x10

#define SIM_MAX_SLAVES (WORLD_MAX_BOARDS - 1)

typedef struct sim_t {
	const sim_board_desc_t *board;	/* the gateway's */
	world_t world;
	sim_board_t gateway;
	sim_board_t slave[SIM_MAX_SLAVES];
	int twar_checked[WORLD_MAX_BOARDS];	/* slave's TWAR compared with --slave */
	pty_t pty;
	signal_t bus_busy;		/* "i2c", a signal of the gateway's */
	signal_t bus_sda, bus_scl;	/* the lines "sda" and "scl", the gateway's too */
	vcd_t vcd;
	control_t control;
	int idle_throttle;
	int real_time;		/* --real-time: simulated time never ahead of wall time */
	int no_park;			/* --no-park: run every board every quantum */
} sim_t;

static volatile sig_atomic_t sim_stop;

static void sim_on_signal(int sig)
{
	(void)sig;
	sim_stop = 1;
}

/* The kinds of parts that attach to ATTACH, one line each. */
static void sim_usage_kinds(part_attach_t attach)
{
	for (int i = 0; part_kinds[i]; i++) {
		const part_kind_t *k = part_kinds[i];
		char name[40], addrs_buf[64], senses_buf[80];
		const char *addrs = part_kind_addrs(k, addrs_buf, sizeof(addrs_buf));
		const char *senses = part_kind_senses(k, senses_buf, sizeof(senses_buf));

		if (k->attach != attach) {
			continue;
		}
		snprintf(name, sizeof(name), "%s%s%s%s", k->name, *k->options ? "[:" : "", k->options,
			 *k->options ? "]" : "");
		fprintf(stderr, "  %-14s %s%s%s%s%s\n", name, k->about, addrs ? "; at " : "",
			addrs ? addrs : "", senses ? "; senses " : "", senses ? senses : "");
	}
}

static void sim_usage(void)
{
	fprintf(stderr,
		"usage: orfa-sim --board %s --link PATH [--part KIND@ADDR[:OPTIONS]]...\n"
		"                [--eeprom ADDR[:wp]]... [--srf08 ADDR]...\n"
		"                [--trace FILE] [--no-idle-throttle] [--real-time] [--no-park]\n"
		"                [--control PATH] [--vcd FILE] [--spi [SLAVE/]KIND@PIN[:mode=N][:lsb]]...\n"
		"                [--adc CH=MV]... [--avcc MV] [--aref MV]\n"
		"                [--slave BOARD:ADDR:ELF]... GATEWAY.elf\n"
		"\n"
		"GATEWAY.elf runs on the --board board, whose serial port is the pty at\n"
		"--link. Each --slave adds a board (%s) running ELF on the same\n"
		"I2C bus; ADDR is its 8-bit address (0x%02X..0x%02X, even): it names the\n"
		"board's signals in the control interface (`10/servo3`, `@10`) and is\n"
		"checked against the firmware's TWAR (the firmware decides). The\n"
		"--adc/--avcc/--aref options set up the gateway board, --spi too\n"
		"unless prefixed with a slave's address (--spi 12/eeprom25@C2); the\n"
		"control interface reaches every board. --part puts a part of KIND on\n"
		"the I2C bus at ADDR (8-bit, even); --eeprom ADDR[:wp] is short for\n"
		"--part eeprom24@ADDR[:wp], --srf08 ADDR for --part srf08@ADDR.\n"
		"See docs/simulator.md.\n"
		"\nParts on the I2C bus (--part KIND@ADDR[:OPTIONS]):\n",
		sim_board_names(), sim_board_names(), I2C_ADDR_MIN, I2C_ADDR_MAX);
	sim_usage_kinds(PART_I2C);
	fprintf(stderr, "Parts on a board's SPI bus (--spi KIND@PIN[:mode=N][:lsb]):\n");
	sim_usage_kinds(PART_SPI);
}

static void sim_to_host(void *param, uint8_t byte)
{
	pty_write(param, byte);
}

/* A slave board's serial port is not connected. */
static void sim_discard(void *param, uint8_t byte)
{
	(void)param;
	(void)byte;
}

/* Once a slave's firmware enables its TWI as a slave, say so on stderr if
 * it answers at another address than its --slave: the firmware's TWAR
 * decides, the option only names the board. */
static void sim_check_twar(sim_t *sim)
{
	world_t *w = &sim->world;

	for (int i = 1; i < w->nboards; i++) {
		sim_board_t *b = w->boards[i];
		uint8_t cr = b->avr->data[b->mcu->twi.twcr];
		uint8_t twar = b->avr->data[b->mcu->twi.twar] & 0xfe;

		if (sim->twar_checked[i] || !(cr & 0x04) || !(cr & 0x40)) {
			continue;	/* TWEN and TWEA not both set yet */
		}
		sim->twar_checked[i] = 1;
		if (twar != b->addr) {
			fprintf(stderr, "orfa-sim: slave %s: its firmware answers at 0x%02X"
				" (TWAR), not 0x%02X\n", b->prefix, twar, b->addr);
		}
	}
}

static double sim_now(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int sim_parse_addr(const char *s, uint8_t *out)
{
	char *end;
	unsigned long v = strtoul(s, &end, 0);

	if (!*s || *end || v > 0xff || (v & 1)) {
		return -1;
	}
	*out = (uint8_t)v;
	return 0;
}

/* Run about a millisecond of simulated time and hand the gateway's output
 * to the pty. 0, or 1 when a firmware crashed or stopped for good. */
static int sim_batch(sim_t *sim)
{
	world_t *w = &sim->world;
	uint64_t target = world_cycle(w) + SIM_BATCH_CYCLES;
	uint64_t deadline = control_deadline(&sim->control);
	int rc;

	/* a control client's `wait` ends near its cycle, not a batch later */
	if (deadline < target) {
		target = deadline;
	}
	/* ... and a `wait i2c` at the quantum its last byte came in */
	rc = world_run(w, target, control_bytes_due(&sim->control));
	pty_flush(&sim->pty);
	sim_check_twar(sim);
	vcd_flush(&sim->vcd, world_cycle(w), 0);
	if (rc) {
		sim_board_t *b = w->boards[w->dead];

		fprintf(stderr, "orfa-sim: %s%sfirmware %s at pc 0x%04x, cycle %" PRIu64 "\n",
			b->prefix, b->prefix[0] ? ": " : "",
			w->dead_state == cpu_Crashed ? "crashed" :
			"stopped (sleep with interrupts off)",
			b->avr->pc, (uint64_t)b->avr->cycle);
		return 1;
	}
	return 0;
}

static uint32_t sim_activity(const sim_t *sim)
{
	return world_activity(&sim->world) + sim->control.activity;
}

#define SIM_MAX_SPI 8

/* A part on the I2C bus from --part KIND@ADDR[:OPTIONS] or a shorthand. */
typedef struct sim_part_arg_t {
	const part_kind_t *kind;
	uint8_t addr8;
	const char *opts;		/* the text after ADDR's ':', or "" */
} sim_part_arg_t;

typedef struct sim_args_t {
	const char *link, *trace, *firmware, *control, *vcd;
	sim_part_arg_t part[PART_LIST_MAX];	/* parts on the I2C bus */
	int part_count;
	const char *spi[SIM_MAX_SPI];
	int spi_count;
	uint32_t adc_mv[8];
	uint8_t adc_set;		/* bit per channel given */
	uint32_t avcc, aref;		/* 0: default */
	const sim_board_desc_t *slave_board[SIM_MAX_SLAVES];
	uint8_t slave_addr[SIM_MAX_SLAVES];
	const char *slave_elf[SIM_MAX_SLAVES];
	int slave_count;
} sim_args_t;

/* --part KIND@ADDR[:OPTIONS], or its shorthands --eeprom ADDR[:wp] (KIND
 * eeprom24) and --srf08 ADDR (KIND srf08). 0, or -1 after printing why. */
static int sim_parse_part(sim_args_t *args, const char *opt, const char *spec)
{
	char kind_name[24], addr[16], names[128], addrs[64];
	const char *a = spec, *colon;
	const part_kind_t *kind;
	sim_part_arg_t *pa;
	size_t alen;

	if (!strcmp(opt, "part")) {
		const char *at = strchr(spec, '@');

		if (!at || (size_t)(at - spec) >= sizeof(kind_name)) {
			fprintf(stderr, "orfa-sim: bad --part '%s' (KIND@ADDR[:OPTIONS], KIND one"
				" of %s)\n", spec, part_kind_names(PART_I2C, ", ", names, sizeof(names)));
			return -1;
		}
		memcpy(kind_name, spec, (size_t)(at - spec));
		kind_name[at - spec] = 0;
		a = at + 1;
	} else {
		snprintf(kind_name, sizeof(kind_name), "%s", !strcmp(opt, "eeprom") ? "eeprom24" : opt);
	}
	kind = part_kind_find(kind_name, PART_I2C);
	if (!kind) {
		fprintf(stderr, "orfa-sim: bad --part '%s': no I2C part '%s' (%s)\n", spec, kind_name,
			part_kind_names(PART_I2C, ", ", names, sizeof(names)));
		return -1;
	}
	colon = strchr(a, ':');
	alen = colon ? (size_t)(colon - a) : strlen(a);
	pa = &args->part[args->part_count];
	if (args->part_count == PART_LIST_MAX || alen >= sizeof(addr)) {
		fprintf(stderr, "orfa-sim: bad or too many --%s '%s'\n", opt, spec);
		return -1;
	}
	memcpy(addr, a, alen);
	addr[alen] = 0;
	if (sim_parse_addr(addr, &pa->addr8) < 0 || !part_kind_addr_ok(kind, pa->addr8)) {
		const char *text = part_kind_addrs(kind, addrs, sizeof(addrs));

		fprintf(stderr, "orfa-sim: bad --%s '%s' (ADDR: %s)\n", opt, spec,
			text ? text : "an even 8-bit address like 0xA0");
		return -1;
	}
	pa->kind = kind;
	pa->opts = colon ? colon + 1 : "";
	args->part_count++;
	return 0;
}

/* --slave BOARD:ADDR:ELF. 0, or -1 after printing why. */

static int sim_parse_slave(sim_args_t *args, const char *spec)
{
	char board[16], addr[16];
	const char *c1 = strchr(spec, ':');
	const char *c2 = c1 ? strchr(c1 + 1, ':') : NULL;
	int n = args->slave_count;

	if (!c1 || !c2 || c1 - spec >= (long)sizeof(board) || c2 - c1 - 1 >= (long)sizeof(addr) ||
	    !c2[1]) {
		fprintf(stderr, "orfa-sim: bad --slave '%s' (BOARD:ADDR:ELF, e.g."
			" m128s:0x10:build/m128s-slave/orfa.elf)\n", spec);
		return -1;
	}
	if (n == SIM_MAX_SLAVES) {
		fprintf(stderr, "orfa-sim: too many --slave (at most %d)\n", SIM_MAX_SLAVES);
		return -1;
	}
	memcpy(board, spec, (size_t)(c1 - spec));
	board[c1 - spec] = 0;
	memcpy(addr, c1 + 1, (size_t)(c2 - c1 - 1));
	addr[c2 - c1 - 1] = 0;
	args->slave_board[n] = sim_board_find(board);
	if (!args->slave_board[n]) {
		fprintf(stderr, "orfa-sim: bad --slave '%s': unknown board '%s' (%s)\n", spec,
			board, sim_board_names());
		return -1;
	}
	/* a slave's address: firmware/i2c_addr.h (docs/registers.md, "On a slave board") */
	if (sim_parse_addr(addr, &args->slave_addr[n]) < 0 || !I2C_ADDR_OK(args->slave_addr[n])) {
		fprintf(stderr, "orfa-sim: bad --slave '%s': ADDR must be an even 8-bit address"
			" 0x%02X..0x%02X like 0x10\n", spec, I2C_ADDR_MIN, I2C_ADDR_MAX);
		return -1;
	}
	for (int i = 0; i < n; i++) {
		if (args->slave_addr[i] == args->slave_addr[n]) {
			fprintf(stderr, "orfa-sim: bad --slave '%s': two slaves at 0x%02X\n", spec,
				args->slave_addr[n]);
			return -1;
		}
	}
	args->slave_elf[n] = c2 + 1;
	args->slave_count++;
	return 0;
}

/* "1234" millivolts, 0..100000. 0 or -1. */
static int sim_parse_mv(const char *s, uint32_t *out)
{
	char *end;
	unsigned long v = strtoul(s, &end, 10);

	if (!*s || *end || *s == '-' || v > 100000) {
		return -1;
	}
	*out = (uint32_t)v;
	return 0;
}

/* Parse the command line into ARGS and SIM's board/throttle. 0, or the
 * exit status to leave with. */
static int sim_parse_args(sim_t *sim, sim_args_t *args, int argc, char **argv)
{
	static const struct option opts[] = {
		{ "board", required_argument, NULL, 'b' },
		{ "link", required_argument, NULL, 'l' },
		{ "eeprom", required_argument, NULL, 'e' },
		{ "srf08", required_argument, NULL, 'F' },
		{ "part", required_argument, NULL, 'P' },
		{ "trace", required_argument, NULL, 't' },
		{ "no-idle-throttle", no_argument, NULL, 'n' },
		{ "real-time", no_argument, NULL, 'r' },
		{ "no-park", no_argument, NULL, 'N' },
		{ "control", required_argument, NULL, 'c' },
		{ "vcd", required_argument, NULL, 'v' },
		{ "spi", required_argument, NULL, 's' },
		{ "adc", required_argument, NULL, 'a' },
		{ "avcc", required_argument, NULL, 'V' },
		{ "aref", required_argument, NULL, 'R' },
		{ "slave", required_argument, NULL, 'S' },
		{ "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 },
	};
	int c;

	sim->idle_throttle = 1;
	while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
		switch (c) {
		case 'b':
			sim->board = sim_board_find(optarg);
			if (!sim->board) {
				fprintf(stderr, "orfa-sim: unknown board '%s' (%s)\n",
					optarg, sim_board_names());
				return 2;
			}
			break;
		case 'l':
			args->link = optarg;
			break;
		case 'e':
		case 'F':
		case 'P':
			if (sim_parse_part(args, c == 'e' ? "eeprom" : c == 'F' ? "srf08" : "part",
					   optarg) < 0) {
				return 2;
			}
			break;
		case 't':
			args->trace = optarg;
			break;
		case 'n':
			sim->idle_throttle = 0;
			break;
		case 'r':
			sim->real_time = 1;
			break;
		case 'N':
			sim->no_park = 1;
			break;
		case 'c':
			args->control = optarg;
			break;
		case 'v':
			args->vcd = optarg;
			break;
		case 's':
			if (args->spi_count == SIM_MAX_SPI) {
				fprintf(stderr, "orfa-sim: too many --spi\n");
				return 2;
			}
			args->spi[args->spi_count++] = optarg;
			break;
		case 'a': {
			const char *eq = strchr(optarg, '=');

			if (!eq || eq - optarg != 1 || optarg[0] < '0' || optarg[0] > '7' ||
			    sim_parse_mv(eq + 1, &args->adc_mv[optarg[0] - '0']) < 0) {
				fprintf(stderr, "orfa-sim: bad --adc '%s' (CH=MV, CH 0..7)\n", optarg);
				return 2;
			}
			args->adc_set |= (uint8_t)(1u << (optarg[0] - '0'));
			break;
		}
		case 'V':
		case 'R':
			if (sim_parse_mv(optarg, c == 'V' ? &args->avcc : &args->aref) < 0 ||
			    !(c == 'V' ? args->avcc : args->aref)) {
				fprintf(stderr, "orfa-sim: bad --%s '%s' (millivolts)\n",
					c == 'V' ? "avcc" : "aref", optarg);
				return 2;
			}
			break;
		case 'S':
			if (sim_parse_slave(args, optarg) < 0) {
				return 2;
			}
			break;
		case 'h':
			sim_usage();
			exit(0);
		default:
			sim_usage();
			return 2;
		}
	}
	/* one device per address: parts and slaves */
	for (int i = 0; i < args->part_count; i++) {
		const sim_part_arg_t *pi = &args->part[i];

		for (int j = 0; j < i; j++) {
			if (args->part[j].addr8 == pi->addr8) {
				fprintf(stderr, "orfa-sim: two parts at 0x%02X (%s, %s)\n", pi->addr8,
					args->part[j].kind->name, pi->kind->name);
				return 2;
			}
		}
		for (int j = 0; j < args->slave_count; j++) {
			if (args->slave_addr[j] == pi->addr8) {
				fprintf(stderr, "orfa-sim: a --slave and a part (%s) at 0x%02X\n",
					pi->kind->name, pi->addr8);
				return 2;
			}
		}
	}
	if (!sim->board || !args->link || optind != argc - 1) {
		sim_usage();
		return 2;
	}
	args->firmware = argv[optind];
	return 0;
}

/* One VCD for every board: the gateway's signals in scope `board` under
 * their own names, a slave's in scope `board_10` as `10/servo3`; each
 * scope's comment names its board ("board m32d OR-AVR-M32-D"). */
static int sim_open_vcd(sim_t *sim, const char *path)
{
	static char scope[WORLD_MAX_BOARDS][16], prefix[WORLD_MAX_BOARDS][8];
	static char about[WORLD_MAX_BOARDS][48];
	signals_t *sets[WORLD_MAX_BOARDS];
	const char *scopes[WORLD_MAX_BOARDS], *prefixes[WORLD_MAX_BOARDS];
	const char *abouts[WORLD_MAX_BOARDS];
	world_t *w = &sim->world;

	for (int i = 0; i < w->nboards; i++) {
		sim_board_t *b = w->boards[i];

		snprintf(scope[i], sizeof(scope[i]), i ? "board_%s" : "board", b->prefix);
		snprintf(prefix[i], sizeof(prefix[i]), i ? "%s/" : "", b->prefix);
		snprintf(about[i], sizeof(about[i]), "board %s %s", b->board->name,
			 b->board->title);
		sets[i] = &b->bm.signals;
		scopes[i] = scope[i];
		prefixes[i] = prefix[i];
		abouts[i] = about[i];
	}
	return vcd_open(&sim->vcd, path, SIM_FREQUENCY, sets, scopes, prefixes, abouts,
			w->nboards);
}

/* Build the world: the bus and its EEPROMs, the gateway board with its
 * options, the control socket. 0, or the exit status. */
static int sim_build(sim_t *sim, const sim_args_t *args)
{
	world_t *w = &sim->world;
	sim_board_t *gw = &sim->gateway;
	int rc;

	world_init(w);
	w->no_park = sim->no_park;
	if (args->trace && trace_open(&w->trace, args->trace) < 0) {
		fprintf(stderr, "orfa-sim: cannot write trace '%s': %s\n",
			args->trace, strerror(errno));
		return 2;
	}
	for (int i = 0; i < args->part_count; i++) {
		const sim_part_arg_t *pa = &args->part[i];
		const char *err = world_add_part(w, pa->kind, pa->addr8, pa->opts);

		if (err) {
			fprintf(stderr, "orfa-sim: bad part %s at 0x%02X: %s\n", pa->kind->name,
				pa->addr8, err);
			return 2;
		}
	}
	rc = sim_board_init(gw, sim->board, args->firmware, 0, &w->bus, &w->trace,
			    sim_to_host, &sim->pty);
	if (rc) {
		return rc;
	}
	w->boards[w->nboards++] = gw;
	if (signal_add(&gw->bm.signals, &sim->bus_busy, "i2c", 0) < 0 ||
	    signal_add(&gw->bm.signals, &sim->bus_sda, "sda", 1) < 0 ||
	    signal_add(&gw->bm.signals, &sim->bus_scl, "scl", 1) < 0) {
		fprintf(stderr, "orfa-sim: too many signals\n");
		return 1;
	}
	w->bus.busy_signal = &sim->bus_busy;
	w->bus.sda_signal = &sim->bus_sda;
	w->bus.scl_signal = &sim->bus_scl;
	for (int i = 0; i < args->slave_count; i++) {
		rc = sim_board_init(&sim->slave[i], args->slave_board[i], args->slave_elf[i],
				    args->slave_addr[i], &w->bus, &w->trace, sim_discard, NULL);
		if (rc) {
			return rc;
		}
		w->boards[w->nboards++] = &sim->slave[i];
	}
	for (int i = 0; i < args->spi_count; i++) {
		/* "12/eeprom25@C2": a device on slave 12's SPI bus */
		const char *spec = args->spi[i];
		const char *slash = strchr(spec, '/');
		sim_board_t *on = gw;
		const char *err;

		if (slash) {
			on = NULL;
			for (int k = 1; k < w->nboards; k++) {
				size_t n = strlen(w->boards[k]->prefix);

				if ((size_t)(slash - spec) == n &&
				    !strncasecmp(spec, w->boards[k]->prefix, n)) {
					on = w->boards[k];
				}
			}
			if (!on) {
				fprintf(stderr, "orfa-sim: bad --spi '%s': no --slave %.*s\n", spec,
					(int)(slash - spec), spec);
				return 2;
			}
			spec = slash + 1;
		}
		err = board_model_add_spi(&on->bm, spec);

		if (err) {
			fprintf(stderr, "orfa-sim: bad --spi '%s': %s\n", args->spi[i], err);
			return 2;
		}
	}
	for (int ch = 0; ch < 8; ch++) {
		if (args->adc_set & (1u << ch)) {
			board_model_set_adc(&gw->bm, ch, args->adc_mv[ch]);
		}
	}
	if (args->avcc) {
		board_model_set_avcc(&gw->bm, args->avcc);
	}
	if (args->aref) {
		board_model_set_aref(&gw->bm, args->aref);
	}
	if (args->vcd && sim_open_vcd(sim, args->vcd) < 0) {
		fprintf(stderr, "orfa-sim: cannot write VCD '%s': %s\n", args->vcd, strerror(errno));
		return 2;
	}
	sim->control.fd = -1;
	if (args->control &&
	    control_open(&sim->control, args->control, gw->avr, &gw->bm, &gw->usart, &w->bus,
			 &w->parts) < 0) {
		fprintf(stderr, "orfa-sim: cannot listen on '%s': %s\n", args->control,
			strerror(errno));
		return 2;
	}
	sim->control.pty = &sim->pty;
	for (int i = 1; i < w->nboards; i++) {
		control_add_board(&sim->control, w->boards[i]->addr, w->boards[i]->avr,
				  &w->boards[i]->bm);
	}
	for (int i = 0; i < w->nboards && i < sim->control.nboards; i++) {
		sim->control.board[i].twi_isr = &w->boards[i]->twi.isr;
	}
	return 0;
}

/* Idle throttle: after SIM_IDLE_AFTER_S of wall time with nothing on the
 * serial line or the bus (and no `wait` or scheduled byte ahead), simulated
 * time is held to wall time; with --real-time always (th->on from the start). */
typedef struct sim_throttle_t {
	uint32_t last_activity;
	double t_last_activity;
	int on;
	double wall0;
	avr_cycle_count_t cycle0;
} sim_throttle_t;

static void sim_throttle(sim_t *sim, sim_throttle_t *th, int host_bytes, double now)
{
	uint32_t act = sim_activity(sim);

	if (sim->real_time) {
		/* held to wall time from the start, activity or not */
	} else if (host_bytes || act != th->last_activity || control_waiting(&sim->control) ||
	    usart_inject_pending(&sim->gateway.usart)) {
		th->last_activity = act;
		th->t_last_activity = now;
		th->on = 0;
	} else if (sim->idle_throttle && !th->on &&
		   now - th->t_last_activity > SIM_IDLE_AFTER_S) {
		th->on = 1;
		th->wall0 = now;
		th->cycle0 = world_cycle(&sim->world);
	}
	if (th->on) {
		double ahead = (double)(world_cycle(&sim->world) - th->cycle0) / SIM_FREQUENCY -
			       (now - th->wall0);
		if (sim->real_time && ahead < -SIM_REAL_TIME_BEHIND_S) {
			/* Fallen behind (the machine busy): go on at real time
			 * from here rather than run free to catch up, which
			 * would give the PC less than a real board's time. */
			th->wall0 = now;
			th->cycle0 = world_cycle(&sim->world);
		}
		if (ahead > 0.0005) {
			/* Wait for wall time, or for the PC or a control
			 * client to send. */
			struct pollfd pfd[2 + CONTROL_CLIENTS] = {
				{ .fd = sim->pty.master, .events = POLLIN },
			};
			int n = 1 + control_pollfds(&sim->control, pfd + 1, CONTROL_CLIENTS + 1);

			poll(pfd, (nfds_t)n, (int)(ahead * 1000));
		}
	}
}

/* Run until a signal (0) or a dead firmware (1); report the speed. */
static int sim_run(sim_t *sim)
{
	sim_throttle_t th = { .last_activity = sim_activity(sim) };
	double t_start = sim_now(), t_free = 0;

	th.on = sim->real_time;
	th.wall0 = t_start;
	th.cycle0 = world_cycle(&sim->world);
	avr_cycle_count_t cyc_free = 0;	/* only time running free counts */
	int rc = 0;

	th.t_last_activity = t_start;
	while (!sim_stop && rc == 0) {
		uint8_t buf[512];
		size_t room = usart_host_room(&sim->gateway.usart);
		size_t n;

		n = pty_read(&sim->pty, buf, room < sizeof(buf) ? room : sizeof(buf));
		/* The PC's rate, before its bytes go on the line, looked up
		 * after they are read: a program sets its rate, then writes, so
		 * the rate seen now is the one its bytes were written at. Looked
		 * up before the read, a program that did both in between
		 * (pyserial opening the port and writing at once) had its first
		 * bytes put on the line at the pty's old rate, all framing
		 * errors. `rx` and `line` look it up again (control.c). */
		usart_set_host_baud(&sim->gateway.usart, pty_baud(&sim->pty));
		if (n) {
			usart_host_send(&sim->gateway.usart, buf, n);
		}
		control_poll(&sim->control);
		double t0 = sim_now();
		avr_cycle_count_t c0 = world_cycle(&sim->world);
		rc = sim_batch(sim);
		double now = sim_now();
		if (!th.on) {
			t_free += now - t0;
			cyc_free += world_cycle(&sim->world) - c0;
		}
		control_poll(&sim->control);
		sim_throttle(sim, &th, n != 0, now);
	}
	/* world cycles: with B boards the MCUs run B times as many */
	fprintf(stderr, "orfa-sim: %" PRIu64 " cycles in %.2f s wall;"
		" running free %.1f simulated MHz per wall second (%.1fx real time),"
		" %d board%s\n",
		(uint64_t)world_cycle(&sim->world), sim_now() - t_start,
		t_free > 0 ? cyc_free / t_free / 1e6 : 0.0,
		t_free > 0 ? cyc_free / t_free / SIM_FREQUENCY : 0.0,
		sim->world.nboards, sim->world.nboards == 1 ? "" : "s");
	return rc;
}

int main(int argc, char **argv)
{
	static sim_t sim;
	sim_args_t args = { 0 };
	struct sigaction sa;
	int rc;

	rc = sim_parse_args(&sim, &args, argc, argv);
	if (rc == 0) {
		rc = sim_build(&sim, &args);
	}
	if (rc) {
		return rc;
	}
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = sim_on_signal;
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGINT, &sa, NULL);
	signal(SIGPIPE, SIG_IGN);

	if (pty_open(&sim.pty) < 0) {
		fprintf(stderr, "orfa-sim: cannot open a pty: %s\n", strerror(errno));
		return 2;
	}
	/* Power-up: let the firmware boot until it enables its receiver (at
	 * most SIM_BOOT_MAX_CYCLES) before the PC can reach the port, so a
	 * first byte sent right after the link appears is not lost to a
	 * board that is still initialising. */
	while (!sim_stop && rc == 0 && world_cycle(&sim.world) < SIM_BOOT_MAX_CYCLES &&
	       !(sim.gateway.avr->data[sim.gateway.usart.regs->ucsrb] & SIM_UCSRB_RXEN)) {
		rc = sim_batch(&sim);
	}
	if (rc == 0 && !sim_stop) {
		if (pty_link(&sim.pty, args.link) < 0) {
			fprintf(stderr, "orfa-sim: cannot create link '%s': %s\n",
				args.link, strerror(errno));
			pty_close(&sim.pty);
			return 2;
		}
		printf("orfa-sim: %s %s @ %u Hz, serial %s -> %s\n", sim.board->name,
		       sim.board->mcu, SIM_FREQUENCY, sim.pty.slave_name, args.link);
		fflush(stdout);
		rc = sim_run(&sim);
	}
	pty_close(&sim.pty);
	control_close(&sim.control);
	vcd_close(&sim.vcd, world_cycle(&sim.world));
	trace_close(&sim.world.trace);
	return rc;
}
