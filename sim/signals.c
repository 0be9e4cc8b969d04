/*
 * signals.c: signals, edge rings, VCD.
 */
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <inttypes.h>

#include "signals.h"

int signal_add(signals_t *set, signal_t *s, const char *name, int level)
{
	if (set->count == SIGNAL_MAX) {
		return -1;
	}
	memset(s, 0, sizeof(*s));
	snprintf(s->name, sizeof(s->name), "%s", name);
	s->level = !!level;
	s->set = set;
	s->index = set->count;
	set->sig[set->count++] = s;
	return 0;
}

signal_t *signal_find(signals_t *set, const char *name)
{
	for (int i = 0; i < set->count; i++) {
		if (strcasecmp(set->sig[i]->name, name) == 0) {
			return set->sig[i];
		}
	}
	return NULL;
}

static void signals_vcd_queue(signals_t *set, const signal_t *s, uint64_t cycle)
{
	if (!set->vcd) {
		return;
	}
	if (set->npending == set->cap) {
		size_t cap = set->cap ? set->cap * 2 : 4096;
		vcd_event_t *p = realloc(set->pending, cap * sizeof(*p));

		if (!p) {
			return;
		}
		set->pending = p;
		set->cap = cap;
	}
	set->pending[set->npending++] = (vcd_event_t) {
		.cycle = cycle, .seq = set->seq++, .sig = (uint16_t)s->index,
		.level = (uint8_t)s->level,
	};
}

void signal_set(signal_t *s, uint64_t cycle, int level)
{
	level = !!level;
	if (level == s->level) {
		return;
	}
	/* Stamps of one signal never go backwards (an edge stamped at its
	 * exact past cycle may meet a later-stamped one of the same cycle). */
	if (cycle < s->last_cycle) {
		cycle = s->last_cycle;
	}
	s->level = level;
	s->last_cycle = cycle;
	s->ring[s->head] = (signal_edge_t) { .cycle = cycle, .level = (uint8_t)level };
	s->head = (s->head + 1) % SIGNAL_RING;
	if (s->count < SIGNAL_RING) {
		s->count++;
	}
	s->total++;
	if (s->set) {
		signals_vcd_queue(s->set, s, cycle);
	}
	for (int i = 0; i < s->listeners; i++) {
		s->listener[i](s->listener_param[i], s, cycle, level);
	}
}

void signal_listen(signal_t *s, signal_listener_t fn, void *param)
{
	if (s->listeners < SIGNAL_LISTENERS) {
		s->listener[s->listeners] = fn;
		s->listener_param[s->listeners] = param;
		s->listeners++;
	}
}

const signal_edge_t *signal_edge(const signal_t *s, unsigned i)
{
	if (i >= s->count) {
		return NULL;
	}
	return &s->ring[(s->head + SIGNAL_RING - 1 - i) % SIGNAL_RING];
}

/* --- VCD ----------------------------------------------------------------- */

static uint32_t vcd_frequency;

/* Picoseconds of CYCLE, rounded: a cycle at 7.3728 MHz is 135633.68 ps, so
 * no VCD timescale holds it exactly; 1 ps keeps the order and the error
 * below half a picosecond. The cycle of every change is also known from
 * the trace and the control interface. */
static uint64_t vcd_ps(uint64_t cycle)
{
	unsigned __int128 t = (unsigned __int128)cycle * 1000000000000ull;

	return (uint64_t)((t + vcd_frequency / 2) / vcd_frequency);
}

static void vcd_id(int index, char *out)
{
	/* printable identifiers '!'..'~', two characters */
	out[0] = (char)('!' + index % 94);
	out[1] = (char)('!' + index / 94);
	out[2] = 0;
}

int signals_vcd_open(signals_t *set, const char *path, uint32_t frequency)
{
	char id[3];

	set->vcd = fopen(path, "w");
	if (!set->vcd) {
		return -1;
	}
	vcd_frequency = frequency;
	fprintf(set->vcd, "$comment orfa-sim, %" PRIu32 " Hz: one CPU cycle is %.3f ps $end\n",
		frequency, 1e12 / frequency);
	fprintf(set->vcd, "$timescale 1ps $end\n$scope module board $end\n");
	for (int i = 0; i < set->count; i++) {
		vcd_id(i, id);
		fprintf(set->vcd, "$var wire 1 %s %s $end\n", id, set->sig[i]->name);
	}
	fprintf(set->vcd, "$upscope $end\n$enddefinitions $end\n#0\n$dumpvars\n");
	for (int i = 0; i < set->count; i++) {
		vcd_id(i, id);
		fprintf(set->vcd, "%d%s\n", set->sig[i]->level, id);
	}
	fprintf(set->vcd, "$end\n");
	return 0;
}

static int vcd_cmp(const void *a, const void *b)
{
	const vcd_event_t *x = a, *y = b;

	if (x->cycle != y->cycle) {
		return x->cycle < y->cycle ? -1 : 1;
	}
	return x->seq < y->seq ? -1 : (x->seq > y->seq);
}

void signals_vcd_flush(signals_t *set, uint64_t now, int all)
{
	size_t n = 0;
	char id[3];

	if (!set->vcd || !set->npending) {
		return;
	}
	qsort(set->pending, set->npending, sizeof(*set->pending), vcd_cmp);
	while (n < set->npending &&
	       (all || set->pending[n].cycle + SIGNALS_VCD_LAG < now)) {
		const vcd_event_t *e = &set->pending[n++];
		uint64_t cycle = e->cycle < set->vcd_last ? set->vcd_last : e->cycle;

		if (!set->vcd_have_time || cycle != set->vcd_last) {
			fprintf(set->vcd, "#%" PRIu64 "\n", vcd_ps(cycle));
			set->vcd_last = cycle;
			set->vcd_have_time = 1;
		}
		vcd_id(e->sig, id);
		fprintf(set->vcd, "%d%s\n", e->level, id);
	}
	memmove(set->pending, set->pending + n, (set->npending - n) * sizeof(*set->pending));
	set->npending -= n;
}

void signals_vcd_close(signals_t *set, uint64_t now)
{
	if (!set->vcd) {
		return;
	}
	signals_vcd_flush(set, now, 1);
	fprintf(set->vcd, "#%" PRIu64 "\n", vcd_ps(now));
	fclose(set->vcd);
	set->vcd = NULL;
	free(set->pending);
	set->pending = NULL;
	set->npending = set->cap = 0;
}
