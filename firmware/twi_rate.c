#include "firmware/twi_rate.h"

twi_rate_t twi_rate_for_khz(uint32_t f_cpu, uint16_t khz)
{
	twi_rate_t r = { .twbr = 255, .twps = 3 };

	/* The shortest SCL period not faster than asked, then the smallest
	 * prescaler whose TWBR reaches it: TWBR = ceil((period - 16) / 2·4^ps)
	 * (ceil of the whole period first changes nothing: ceil(ceil(y)/d) =
	 * ceil(y/d)). One 32-bit division for the period, one for the rate. */
	uint32_t f = (uint32_t)(khz ? khz : 1) * 1000UL;
	uint32_t period = (f_cpu + f - 1) / f;
	uint32_t extra = period > 16 ? period - 16 : 0;

	for (uint8_t ps = 0; ps < 4; ps++) {
		uint8_t shift = (uint8_t)(1 + 2 * ps);
		uint32_t need = (extra + (1UL << shift) - 1) >> shift;
		if (need <= 255) {
			r.twbr = (uint8_t)need;
			r.twps = ps;
			break;
		}
	}
	r.period = 16UL + ((uint32_t)r.twbr << (1 + 2 * r.twps));
	r.khz = (uint16_t)(f_cpu / (r.period * 1000UL));
	return r;
}
