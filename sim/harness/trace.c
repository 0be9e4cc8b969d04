/*
 * trace.c: the trace file writer. Line-buffered so a test reading the file
 * while the simulator runs sees whole events.
 */
#include <stdarg.h>
#include <inttypes.h>

#include "harness/trace.h"

int trace_open(trace_t *t, const char *path)
{
	t->file = fopen(path, "w");
	if (!t->file) {
		return -1;
	}
	setvbuf(t->file, NULL, _IOLBF, 0);
	return 0;
}

void trace_event(trace_t *t, uint64_t cycle, const char *fmt, ...)
{
	va_list ap;

	if (!t || !t->file) {
		return;
	}
	fprintf(t->file, "%" PRIu64 " ", cycle);
	va_start(ap, fmt);
	vfprintf(t->file, fmt, ap);
	va_end(ap);
	fputc('\n', t->file);
}

void trace_close(trace_t *t)
{
	if (t->file) {
		fclose(t->file);
		t->file = NULL;
	}
}
