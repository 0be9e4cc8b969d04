/*
 * signals.h: named digital signals of the board (port pins, counter outputs)
 * with cycle-stamped edge records, change listeners and a VCD writer.
 *
 * A signal changes only through signal_set(); equal levels are ignored, so
 * every record is a real edge. Each signal keeps its last SIGNAL_RING edges.
 */
#ifndef SIM_SIGNALS_H
#define SIM_SIGNALS_H

#include <stdint.h>
#include <stdio.h>

#define SIGNAL_RING 1024
#define SIGNAL_MAX 160
#define SIGNAL_LISTENERS 4

struct signal_t;

/* Called after S changed to LEVEL at CYCLE. */
typedef void (*signal_listener_t)(void *param, struct signal_t *s,
				  uint64_t cycle, int level);

typedef struct signal_edge_t {
	uint64_t cycle;
	uint8_t level;
} signal_edge_t;

typedef struct signal_t {
	char name[16];
	int level;
	uint64_t last_cycle;		/* cycle of the last edge (0: none) */
	signal_edge_t ring[SIGNAL_RING];
	unsigned head;			/* next slot to write */
	unsigned count;			/* edges held (<= SIGNAL_RING) */
	uint64_t total;			/* edges ever */
	signal_listener_t listener[SIGNAL_LISTENERS];
	void *listener_param[SIGNAL_LISTENERS];
	int listeners;
	struct signals_t *set;
	int index;
} signal_t;

typedef struct vcd_event_t {
	uint64_t cycle;
	uint64_t seq;
	uint16_t sig;
	uint8_t level;
} vcd_event_t;

/* One VCD file for the signals of one or more boards. Events wait in a
 * buffer until they are old enough to be in time order (some edges are
 * stamped a few cycles in the past, and the boards of a world run a
 * quantum apart). */
typedef struct vcd_t {
	FILE *file;
	uint32_t frequency;
	uint64_t unit_ps;		/* the timescale: 1, 10, 100 ps, 1 ns, ... */
	vcd_event_t *pending;
	size_t npending, cap;
	uint64_t seq, last;
	int have_time;
} vcd_t;

typedef struct signals_t {
	signal_t *sig[SIGNAL_MAX];
	int count;
	vcd_t *vcd;			/* NULL: not in a VCD */
	int vcd_base;			/* its signals' first VCD index */
} signals_t;

/* Register S under NAME with initial LEVEL. 0, or -1 when full. */
int signal_add(signals_t *set, signal_t *s, const char *name, int level);

/* The signal called NAME (case-insensitive), or NULL. */
signal_t *signal_find(signals_t *set, const char *name);

/* Set S to LEVEL at CYCLE; records an edge and notifies when it changed. */
void signal_set(signal_t *s, uint64_t cycle, int level);

void signal_listen(signal_t *s, signal_listener_t fn, void *param);

/* The i-th newest edge held (0 = newest); NULL past the end. */
const signal_edge_t *signal_edge(const signal_t *s, unsigned i);

/* A VCD at PATH of every signal of the N sets (call after all signal_add),
 * its timescale the longest power of ten not longer than one cycle at
 * FREQUENCY (100 ns at 7.3728 MHz; vcd_timescale_ps):
 * set i in scope SCOPE[i], each signal named PREFIX[i] followed by its own
 * name, the scope's comment ABOUT[i] (ABOUT or ABOUT[i] NULL: none). 0 or
 * -1 with errno. */
int vcd_open(vcd_t *v, const char *path, uint32_t frequency, signals_t *const *sets,
	     const char *const *scope, const char *const *prefix,
	     const char *const *about, int n);

/* Write buffered VCD events older than NOW - SIGNALS_VCD_LAG cycles (all
 * with ALL). */
#define SIGNALS_VCD_LAG 8192
void vcd_flush(vcd_t *v, uint64_t now, int all);

/* The timescale vcd_open picks at FREQUENCY, in picoseconds. */
uint64_t vcd_timescale_ps(uint32_t frequency);
void vcd_close(vcd_t *v, uint64_t now);

#endif
