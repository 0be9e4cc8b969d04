/*
 * signals.c: signals, edge rings, VCD.
 */
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <inttypes.h>

#include "harness/signals.h"

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
	vcd_t *v = set->vcd;

	if (!v) {
		return;
	}
	if (v->npending == v->cap) {
		size_t cap = v->cap ? v->cap * 2 : 4096;
		vcd_event_t *p = realloc(v->pending, cap * sizeof(*p));

		if (!p) {
			return;
		}
		v->pending = p;
		v->cap = cap;
	}
	v->pending[v->npending++] = (vcd_event_t) {
		.cycle = cycle, .seq = v->seq++, .sig = (uint16_t)(set->vcd_base + s->index),
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

/*
 * A cycle at 7.3728 MHz is 135.6337 ns, which no VCD timescale (1, 10 or
 * 100 of s, ms, us, ns, ps, fs) holds. sigrok takes the timescale as its
 * sample rate and walks every sample, so 1 ps made it take minutes over a
 * simulated second. The file uses the longest power of ten not longer than
 * a cycle (100 ns: 10 MHz, one simulated second decodes in well under a
 * second) and rounds each cycle's time to the nearest unit: a unit being
 * at most a cycle, distinct cycles get distinct times in order, and
 * rounding time / cycle back gives the exact cycle (the error is at most
 * half a unit, under half a cycle).
 */
uint64_t vcd_timescale_ps(uint32_t frequency)
{
	uint64_t unit = 1000000000ull;	/* 1 ms: a clock of 1 kHz or more */

	while (unit > 1 && unit * frequency > 1000000000000ull) {
		unit /= 10;
	}
	return unit;
}

static const char *vcd_timescale_text(uint64_t unit_ps, char *buf, size_t size)
{
	static const char *const names[] = { "ps", "ns", "us", "ms", "s" };
	int k = 0;

	while (unit_ps >= 1000 && k < 4) {
		unit_ps /= 1000;
		k++;
	}
	snprintf(buf, size, "%" PRIu64 "%s", unit_ps, names[k]);
	return buf;
}

/* CYCLE in timescale units, rounded. */
static uint64_t vcd_time(const vcd_t *v, uint64_t cycle)
{
	unsigned __int128 t = (unsigned __int128)cycle * 1000000000000ull;
	unsigned __int128 per = (unsigned __int128)v->frequency * v->unit_ps;

	return (uint64_t)((t + per / 2) / per);
}

static void vcd_id(int index, char *out)
{
	/* printable identifiers '!'..'~', two characters */
	out[0] = (char)('!' + index % 94);
	out[1] = (char)('!' + index / 94);
	out[2] = 0;
}

int vcd_open(vcd_t *v, const char *path, uint32_t frequency, signals_t *const *sets,
	     const char *const *scope, const char *const *prefix,
	     const char *const *about, int n)
{
	char id[3], unit[32];
	int base = 0;

	memset(v, 0, sizeof(*v));
	v->file = fopen(path, "w");
	if (!v->file) {
		return -1;
	}
	v->frequency = frequency;
	v->unit_ps = vcd_timescale_ps(frequency);
	fprintf(v->file, "$comment orfa-sim, %" PRIu32 " Hz: one CPU cycle is %.3f ps; "
		"a time is the cycle's, rounded to the timescale $end\n",
		frequency, 1e12 / frequency);
	fprintf(v->file, "$timescale %s $end\n", vcd_timescale_text(v->unit_ps, unit, sizeof(unit)));
	for (int k = 0; k < n; k++) {
		signals_t *set = sets[k];

		set->vcd = v;
		set->vcd_base = base;
		fprintf(v->file, "$scope module %s $end\n", scope[k]);
		if (about && about[k]) {
			fprintf(v->file, "$comment %s $end\n", about[k]);
		}
		for (int i = 0; i < set->count; i++) {
			vcd_id(base + i, id);
			fprintf(v->file, "$var wire 1 %s %s%s $end\n", id, prefix[k],
				set->sig[i]->name);
		}
		fprintf(v->file, "$upscope $end\n");
		base += set->count;
	}
	fprintf(v->file, "$enddefinitions $end\n#0\n$dumpvars\n");
	for (int k = 0; k < n; k++) {
		for (int i = 0; i < sets[k]->count; i++) {
			vcd_id(sets[k]->vcd_base + i, id);
			fprintf(v->file, "%d%s\n", sets[k]->sig[i]->level, id);
		}
	}
	fprintf(v->file, "$end\n");
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

void vcd_flush(vcd_t *v, uint64_t now, int all)
{
	size_t n = 0;
	char id[3];

	if (!v->file || !v->npending) {
		return;
	}
	qsort(v->pending, v->npending, sizeof(*v->pending), vcd_cmp);
	while (n < v->npending && (all || v->pending[n].cycle + SIGNALS_VCD_LAG < now)) {
		const vcd_event_t *e = &v->pending[n++];
		uint64_t cycle = e->cycle < v->last ? v->last : e->cycle;

		if (!v->have_time || cycle != v->last) {
			fprintf(v->file, "#%" PRIu64 "\n", vcd_time(v, cycle));
			v->last = cycle;
			v->have_time = 1;
		}
		vcd_id(e->sig, id);
		fprintf(v->file, "%d%s\n", e->level, id);
	}
	memmove(v->pending, v->pending + n, (v->npending - n) * sizeof(*v->pending));
	v->npending -= n;
}

void vcd_close(vcd_t *v, uint64_t now)
{
	if (!v->file) {
		return;
	}
	vcd_flush(v, now, 1);
	fprintf(v->file, "#%" PRIu64 "\n", vcd_time(v, now));
	fclose(v->file);
	v->file = NULL;
	free(v->pending);
	v->pending = NULL;
	v->npending = v->cap = 0;
}
