/* profile.c: cycles a board spends at each flash word (profile.h). */
#include "harness/profile.h"

#include <stdlib.h>
#include <string.h>

#define PROFILE_MAX_BOARDS 16

typedef struct profile_t {
	avr_t *avr;
	uint64_t *cycles;	/* per flash word */
	uint32_t words;
	int on;
	avr_flashaddr_t pc;	/* the instruction last noted, its cycle */
	uint64_t at;
} profile_t;

static profile_t profiles[PROFILE_MAX_BOARDS];
int profile_boards;

/* The instruction AVR's next cycles belong to: asleep, its SLEEP (one
 * word; the PC is past it), else the one at the PC. */
static avr_flashaddr_t profile_pc(const avr_t *avr)
{
	return avr->state == cpu_Sleeping ? avr->pc - 2 : avr->pc;
}

static profile_t *profile_of(avr_t *avr)
{
	for (int i = 0; i < PROFILE_MAX_BOARDS; i++) {
		if (profiles[i].avr == avr) {
			return &profiles[i];
		}
	}
	return NULL;
}

int profile_on(avr_t *avr)
{
	profile_t *p = profile_of(avr);

	if (!p) {
		p = profile_of(NULL);
		if (!p) {
			return -1;
		}
		p->words = (avr->flashend + 1) / 2;
		p->cycles = calloc(p->words, sizeof *p->cycles);
		if (!p->cycles) {
			return -1;
		}
		p->avr = avr;
	}
	memset(p->cycles, 0, p->words * sizeof *p->cycles);
	p->pc = profile_pc(avr);
	p->at = avr->cycle;
	if (!p->on) {
		p->on = 1;
		profile_boards++;
	}
	return 0;
}

void profile_off(avr_t *avr)
{
	profile_t *p = profile_of(avr);

	if (p && p->on) {
		profile_note_slow(avr);	/* the cycles up to now */
		p->on = 0;
		profile_boards--;
	}
}

const uint64_t *profile_counts(avr_t *avr, uint32_t *words)
{
	profile_t *p = profile_of(avr);

	if (!p) {
		return NULL;
	}
	if (p->on) {
		profile_note_slow(avr);
	}
	*words = p->words;
	return p->cycles;
}

void profile_note_slow(avr_t *avr)
{
	profile_t *p = profile_of(avr);

	if (!p || !p->on) {
		return;
	}
	if (p->pc / 2 < p->words) {
		p->cycles[p->pc / 2] += avr->cycle - p->at;
	}
	p->pc = profile_pc(avr);
	p->at = avr->cycle;
}
