/*
 * trace.h: the cycle-stamped event trace (--trace FILE), one event a line.
 */
#ifndef SIM_TRACE_H
#define SIM_TRACE_H

#include <stdint.h>
#include <stdio.h>

typedef struct trace_t {
	FILE *file;	/* NULL: tracing off, every call is a no-op */
} trace_t;

/* Open PATH for writing, line-buffered. Returns 0, or -1 with errno set. */
int trace_open(trace_t *t, const char *path);

/* Write "<cycle> <formatted text>\n" (nothing when tracing is off). */
void trace_event(trace_t *t, uint64_t cycle, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

void trace_close(trace_t *t);

#endif
