#include "firmware/twi_rate.h"

twi_rate_t twi_rate_for_khz(uint32_t f_cpu, uint16_t khz)
{
	uint32_t f = (uint32_t)khz * 1000UL;
	twi_rate_t r = { .twbr = 255, .twps = 3 };

	for (uint8_t ps = 0; ps < 4; ps++) {
		uint32_t mul_f = (2UL << (2 * ps)) * f;
		uint32_t need = 0;
		if (16UL * f < f_cpu) {
			need = (f_cpu - 16UL * f + mul_f - 1) / mul_f;  /* rounded up */
		}
		if (need <= 255) {
			r.twbr = (uint8_t)need;
			r.twps = ps;
			break;
		}
	}
	r.period = 16UL + ((uint32_t)r.twbr << (1 + 2 * r.twps));
	r.khz = (uint16_t)(f_cpu / r.period / 1000UL);
	return r;
}
