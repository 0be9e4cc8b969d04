/*
 * main.c: orfa-sim, an ORFA board under simavr 1.6 (docs/simulator.md).
 *
 * Single-threaded: avr_run() in batches of about a millisecond of simulated
 * time; between batches the pty is serviced, the idle throttle decides
 * whether to wait for wall time, and signals are noticed. The pty is never
 * serviced from cycle timers because a watchdog reset wipes them.
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
#include <time.h>

#include "sim_avr.h"
#include "sim_elf.h"

#include "board.h"
#include "mcu.h"
#include "pty.h"
#include "trace.h"
#include "twi.h"
#include "twi_bus.h"
#include "usart.h"
#include "parts/eeprom24.h"

#define SIM_FREQUENCY 7372800u
#define SIM_MAX_EEPROMS 8
#define SIM_BATCH_CYCLES (SIM_FREQUENCY / 1000)	/* 1 ms simulated */
#define SIM_IDLE_AFTER_S 0.5
#define SIM_BOOT_MAX_CYCLES (SIM_FREQUENCY / 10)	/* 100 ms simulated */
#define SIM_UCSRB_RXEN 0x10

typedef struct sim_t {
	const board_desc_t *board;
	const mcu_desc_t *mcu;
	avr_t *avr;
	avr_io_t reset_watch;		/* traces "reset" on a watchdog reset */
	trace_t trace;
	pty_t pty;
	usart_t usart;
	twi_bus_t bus;
	twi_t twi;
	eeprom24_t eeprom[SIM_MAX_EEPROMS];
	int eeprom_count;
	int idle_throttle;
} sim_t;

static volatile sig_atomic_t sim_stop;

static void sim_on_signal(int sig)
{
	(void)sig;
	sim_stop = 1;
}

static void sim_usage(void)
{
	fprintf(stderr,
		"usage: orfa-sim --board %s --link PATH [--eeprom ADDR]...\n"
		"                [--trace FILE] [--no-idle-throttle] FIRMWARE.elf\n",
		board_names());
}

/* simavr chatters on stdout (the ELF loader's "Loaded ..."); the contract
 * allows one line there. Errors go to stderr, the rest nowhere. */
static void sim_logger(avr_t *avr, const int level, const char *fmt, va_list ap)
{
	(void)avr;
	if (level <= LOG_ERROR) {
		vfprintf(stderr, fmt, ap);
	}
}

/* The firmware never sleeps; should it, simavr would usleep() to wall time.
 * Simulated time must not depend on wall time, so sleeping costs nothing. */
static void sim_sleep(avr_t *avr, avr_cycle_count_t how_long)
{
	(void)avr;
	(void)how_long;
}

static void sim_reset_hook(avr_io_t *io)
{
	sim_t *sim = (sim_t *)((char *)io - offsetof(sim_t, reset_watch));

	trace_event(&sim->trace, io->avr->cycle, "reset");
}

static void sim_to_host(void *param, uint8_t byte)
{
	pty_write(param, byte);
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

/* Run about a millisecond of simulated time and hand the firmware's output
 * to the pty. 0, or 1 when the firmware crashed or stopped for good. */
static int sim_batch(sim_t *sim)
{
	avr_cycle_count_t target = sim->avr->cycle + SIM_BATCH_CYCLES;
	int state = cpu_Running;

	while (sim->avr->cycle < target) {
		state = avr_run(sim->avr);
		if (state == cpu_Done || state == cpu_Crashed) {
			break;
		}
	}
	pty_flush(&sim->pty);
	if (state == cpu_Done || state == cpu_Crashed) {
		fprintf(stderr, "orfa-sim: firmware %s at pc 0x%04x, cycle %" PRIu64 "\n",
			state == cpu_Crashed ? "crashed" : "stopped (sleep with interrupts off)",
			sim->avr->pc, (uint64_t)sim->avr->cycle);
		return 1;
	}
	return 0;
}

static uint32_t sim_activity(const sim_t *sim)
{
	return sim->usart.activity + sim->bus.activity;
}

int main(int argc, char **argv)
{
	static sim_t sim;
	static const struct option opts[] = {
		{ "board", required_argument, NULL, 'b' },
		{ "link", required_argument, NULL, 'l' },
		{ "eeprom", required_argument, NULL, 'e' },
		{ "trace", required_argument, NULL, 't' },
		{ "no-idle-throttle", no_argument, NULL, 'n' },
		{ "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 },
	};
	const char *link = NULL, *trace_path = NULL;
	uint8_t eeprom_addr[SIM_MAX_EEPROMS];
	elf_firmware_t fw;
	int c;

	sim.idle_throttle = 1;
	while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
		switch (c) {
		case 'b':
			sim.board = board_find(optarg);
			if (!sim.board) {
				fprintf(stderr, "orfa-sim: unknown board '%s' (%s)\n",
					optarg, board_names());
				return 2;
			}
			break;
		case 'l':
			link = optarg;
			break;
		case 'e':
			if (sim.eeprom_count == SIM_MAX_EEPROMS ||
			    sim_parse_addr(optarg, &eeprom_addr[sim.eeprom_count]) < 0) {
				fprintf(stderr, "orfa-sim: bad or too many --eeprom '%s'"
					" (an even 8-bit address like 0xA0)\n", optarg);
				return 2;
			}
			for (int i = 0; i < sim.eeprom_count; i++) {
				if (eeprom_addr[i] == eeprom_addr[sim.eeprom_count]) {
					fprintf(stderr, "orfa-sim: two EEPROMs at %s\n", optarg);
					return 2;
				}
			}
			sim.eeprom_count++;
			break;
		case 't':
			trace_path = optarg;
			break;
		case 'n':
			sim.idle_throttle = 0;
			break;
		case 'h':
			sim_usage();
			return 0;
		default:
			sim_usage();
			return 2;
		}
	}
	if (!sim.board || !link || optind != argc - 1) {
		sim_usage();
		return 2;
	}

	avr_global_logger_set(sim_logger);
	memset(&fw, 0, sizeof(fw));
	if (elf_read_firmware(argv[optind], &fw) != 0 || !fw.flash || !fw.flashsize) {
		fprintf(stderr, "orfa-sim: cannot load firmware '%s'\n", argv[optind]);
		return 2;
	}
	sim.mcu = mcu_find(sim.board->mcu);
	sim.avr = avr_make_mcu_by_name(sim.board->mcu);
	if (!sim.mcu || !sim.avr) {
		fprintf(stderr, "orfa-sim: simavr lacks MCU '%s'\n", sim.board->mcu);
		return 2;
	}
	avr_init(sim.avr);
	if (fw.flashsize > sim.avr->flashend + 1u) {
		fprintf(stderr, "orfa-sim: '%s' does not fit the %s's flash\n",
			argv[optind], sim.board->mcu);
		return 2;
	}
	avr_load_firmware(sim.avr, &fw);
	sim.avr->frequency = SIM_FREQUENCY;	/* our ELFs carry no .mmcu */
	sim.avr->sleep = sim_sleep;

	if (trace_path && trace_open(&sim.trace, trace_path) < 0) {
		fprintf(stderr, "orfa-sim: cannot write trace '%s': %s\n",
			trace_path, strerror(errno));
		return 2;
	}
	twi_bus_init(&sim.bus, &sim.trace);
	for (int i = 0; i < sim.eeprom_count; i++) {
		eeprom24_init(&sim.eeprom[i], eeprom_addr[i]);
		twi_bus_attach(&sim.bus, &sim.eeprom[i].dev);
	}
	usart_init(&sim.usart, sim.avr, &sim.mcu->usart[sim.board->host_usart],
		   &sim.trace, sim_to_host, &sim.pty);
	twi_init(&sim.twi, sim.avr, &sim.mcu->twi, &sim.bus);
	sim.reset_watch.kind = "orfa-reset";
	sim.reset_watch.reset = sim_reset_hook;
	mcu_register_io_last(sim.avr, &sim.reset_watch);

	struct sigaction sa;
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
	int rc = 0;
	while (!sim_stop && rc == 0 && sim.avr->cycle < SIM_BOOT_MAX_CYCLES &&
	       !(sim.avr->data[sim.usart.regs->ucsrb] & SIM_UCSRB_RXEN)) {
		rc = sim_batch(&sim);
	}
	if (rc == 0 && !sim_stop) {
		if (pty_link(&sim.pty, link) < 0) {
			fprintf(stderr, "orfa-sim: cannot create link '%s': %s\n",
				link, strerror(errno));
			pty_close(&sim.pty);
			return 2;
		}
		printf("orfa-sim: %s %s @ %u Hz, serial %s -> %s\n", sim.board->name,
		       sim.board->mcu, SIM_FREQUENCY, sim.pty.slave_name, link);
		fflush(stdout);
	}

	/* Speed bookkeeping: only time spent running free counts. */
	double t_start = sim_now(), t_free = 0;
	avr_cycle_count_t cyc_free = 0;
	/* Idle throttle state. */
	uint32_t last_activity = sim_activity(&sim);
	double t_last_activity = t_start;
	int throttled = 0;
	double th_wall0 = 0;
	avr_cycle_count_t th_cycle0 = 0;

	while (!sim_stop && rc == 0) {
		uint8_t buf[512];
		size_t room = usart_host_room(&sim.usart);
		size_t n = pty_read(&sim.pty, buf, room < sizeof(buf) ? room : sizeof(buf));

		if (n) {
			usart_host_send(&sim.usart, buf, n);
		}

		double t0 = sim_now();
		avr_cycle_count_t c0 = sim.avr->cycle;
		rc = sim_batch(&sim);

		double now = sim_now();
		uint32_t act = sim_activity(&sim);
		if (!throttled) {
			t_free += now - t0;
			cyc_free += sim.avr->cycle - c0;
		}
		if (n || act != last_activity) {
			last_activity = act;
			t_last_activity = now;
			throttled = 0;
		} else if (sim.idle_throttle && !throttled &&
			   now - t_last_activity > SIM_IDLE_AFTER_S) {
			throttled = 1;
			th_wall0 = now;
			th_cycle0 = sim.avr->cycle;
		}
		if (throttled) {
			double ahead = (double)(sim.avr->cycle - th_cycle0) / SIM_FREQUENCY -
				       (now - th_wall0);
			if (ahead > 0.0005) {
				/* Wait for wall time, or for the PC to send. */
				struct pollfd pfd = { .fd = sim.pty.master, .events = POLLIN };
				poll(&pfd, 1, (int)(ahead * 1000));
			}
		}
	}

	double t_total = sim_now() - t_start;
	fprintf(stderr, "orfa-sim: %" PRIu64 " cycles in %.2f s wall;"
		" running free %.1f simulated MHz per wall second (%.1fx real time)\n",
		(uint64_t)sim.avr->cycle, t_total,
		t_free > 0 ? cyc_free / t_free / 1e6 : 0.0,
		t_free > 0 ? cyc_free / t_free / SIM_FREQUENCY : 0.0);
	pty_close(&sim.pty);
	trace_close(&sim.trace);
	return rc;
}
