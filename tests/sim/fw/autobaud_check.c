/*
 * autobaud_check.c: firmware/autobaud.c's pair analysis (ab_check, in
 * assembly) against the rule it implements, written here in plain C with
 * 32-bit arithmetic, on random records and records near every bound, for
 * tests/sim/test_autobaud.py; not ORFA firmware. Built with the gateway's
 * board and rates (Makefile).
 *
 * When done, PORTC is 0xA5, PORTA the records whose rates differ (255 at
 * most) and PORTB the records the rule accepted, in 64s.
 */
#include "firmware/autobaud.c"

#ifndef CHECK_RECORDS
#define CHECK_RECORDS 4096
#endif

/* The rule (docs/protocol.md, "Autobaud"), from the runs as ab_scan stores
 * them: P's five runs, the high run, five more. */
static uint8_t rule(const uint16_t *p)
{
	uint8_t k = 0;
	uint8_t shaped = 0;

	for (uint8_t f = 0; f < 12; f += 6) {
		uint32_t total = 0;

		for (uint8_t j = 0; j < 5; j++) {
			uint16_t c = AB_CYCLES(p[f + j]);

			if (c >= AB_LONG) {
				return 0;
			}
			total += c;
		}
		/* the rate whose window holds the first frame; the second in it */
		uint8_t kf = 0;

		for (uint8_t r = 0; r < AB_NRATES; r++) {
			if (126UL * ab_rates[r] <= total && total <= 162UL * ab_rates[r]) {
				kf = ab_rates[r];
			}
		}
		if (kf == 0 || (f && kf != k)) {
			return 0;
		}
		k = kf;
		/* 0x0D's 1 1 1 2 4 bits, each within a third of a bit and 3 cycles */
		static const uint8_t bits[5] = { 1, 1, 1, 2, 4 };
		int32_t tol = 16L * k / 3 + 3;
		uint8_t fits = 1;

		for (uint8_t j = 0; j < 5; j++) {
			int32_t off = (int32_t)AB_CYCLES(p[f + j]) - 16L * k * bits[j];

			if (off < -tol || off > tol) {
				fits = 0;
			}
		}
		shaped |= fits;
	}
	/* at least half a bit high between the frames */
	if (AB_CYCLES(p[5]) < 8U * k) {
		return 0;
	}
	return shaped ? k : 0;
}

static uint32_t seed = 2463534242UL;

static uint32_t rnd(void)
{
	seed ^= seed << 13;
	seed ^= seed >> 17;
	seed ^= seed << 5;
	return seed;
}

/* A run of CYCLES as ab_scan stores it (the step to the next included):
 * whole iterations, at most the quiet's. */
static uint16_t stored(int32_t cycles)
{
	int32_t its = (cycles - AB_STEP_CYCLES) / AB_LOOP_CYCLES;

	if (its < 0) {
		its = 0;
	}
	if (its >= AB_QUIET) {
		its = AB_QUIET - 1;
	}
	return (uint16_t)(AB_START + its * AB_LOOP_CYCLES);
}

int main(void)
{
	static const uint8_t bits[11] = { 1, 1, 1, 2, 4, 0, 1, 1, 1, 2, 4 };
	uint16_t p[11];
	uint8_t wrong = 0;
	uint16_t accepted = 0;

	for (uint16_t t = 0; t < CHECK_RECORDS; t++) {
		uint8_t kind = (uint8_t)(rnd() % 5);
		int32_t bit = 16L * ab_rates[rnd() % AB_NRATES];
		int32_t scale = 80 + (int32_t)(rnd() % 41);  /* a frame 0.8 to 1.2 long */

		for (uint8_t j = 0; j < 11; j++) {
			int32_t want = bits[j] ? bit * bits[j] : bit / 2 + (int32_t)(rnd() % (uint32_t)(4 * bit));
			int32_t cycles;

			switch (kind) {
			case 0:  /* anything */
				cycles = (int32_t)(rnd() % (AB_QUIET * (uint32_t)AB_LOOP_CYCLES));
				break;
			case 1:  /* short runs of any length */
				cycles = (int32_t)((rnd() % (AB_QUIET * (uint32_t)AB_LOOP_CYCLES)) >> (rnd() % 13));
				break;
			case 2:  /* 0x0D, each run off by up to half a bit */
				cycles = want + (int32_t)(rnd() % (uint32_t)(bit + 25)) - bit / 2 - 12;
				break;
			case 3:  /* 0x0D, each run off by up to a quarter of a bit */
				cycles = want + (int32_t)(rnd() % (uint32_t)(bit / 2 + 9)) - bit / 4 - 4;
				break;
			default:  /* 0x0D at another speed */
				cycles = want * scale / 100 + (int32_t)(rnd() % 13) - 6;
				break;
			}
			p[j] = stored(cycles);
		}
		uint8_t k = rule(p);

		if (k) {
			accepted++;
		}
		if (ab_check(p) != k && wrong < 255) {
			wrong++;
		}
	}
	DDRA = DDRB = DDRC = 0xFF;
	PORTA = wrong;
	PORTB = (uint8_t)(accepted >> 6);
	PORTC = 0xA5;
	for (;;) {  /* (a sleep with interrupts off would end the simulator) */
	}
}
