/*
 * CHECK(cond, printf-args...): one counted check of the small unit test
 * programs (uart-line, orfa-line, orfa-port); a failure prints where and
 * why and the run goes on. Each program reports `checks` and `failures`
 * at its end and exits non-zero when failures != 0.
 */
#ifndef TESTS_UNIT_CHECK_H
#define TESTS_UNIT_CHECK_H

#include <stdio.h>

static int failures, checks;

#define CHECK(cond, ...) do { \
	checks++; \
	if (!(cond)) { \
		failures++; \
		printf("FAIL %s:%d: ", __FILE__, __LINE__); \
		printf(__VA_ARGS__); \
		printf("\n"); \
	} \
} while (0)

#endif
