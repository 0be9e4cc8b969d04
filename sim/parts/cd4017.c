/*
 * cd4017.c: CD4017 decade counter.
 */
#include <stdio.h>
#include <string.h>

#include "parts/cd4017.h"

int cd4017_init(cd4017_t *c, signals_t *set, const char *name)
{
	char buf[16];

	memset(c, 0, sizeof(*c));
	for (int k = 0; k < 10; k++) {
		snprintf(buf, sizeof(buf), "%sq%d", name, k);
		if (signal_add(set, &c->q[k], buf, k == 0) < 0) {
			return -1;
		}
	}
	return 0;
}

static void cd4017_go(cd4017_t *c, uint64_t cycle, int state)
{
	if (state == c->state) {
		return;
	}
	/* falling output first, so no instant has two outputs high */
	signal_set(&c->q[c->state], cycle, 0);
	c->state = state;
	signal_set(&c->q[state], cycle, 1);
}

void cd4017_on_clock(void *param, signal_t *s, uint64_t cycle, int level)
{
	cd4017_t *c = param;

	(void)s;
	if (level && !c->clock && !c->reset) {
		cd4017_go(c, cycle, (c->state + 1) % 10);
	}
	c->clock = level;
}

void cd4017_on_reset(void *param, signal_t *s, uint64_t cycle, int level)
{
	cd4017_t *c = param;

	(void)s;
	c->reset = level;
	if (level) {
		cd4017_go(c, cycle, 0);
	}
}
