#include "firmware/twi_rate.h"

twi_rate_t twi_rate_for_khz(uint32_t f_cpu, uint16_t khz)
{
	twi_rate_t r = { .twbr = 255, .twps = 3 };

	/* The shortest SCL period not faster than asked, then the smallest
	 * prescaler whose TWBR reaches it: TWBR = ceil((period - 16) / 2·4^ps)
	 * (ceil of the whole period first changes nothing: ceil(ceil(y)/d) =
	 * ceil(y/d)). The same rule, and floor's, take the clock to kHz
	 * first, a constant: the divisions left are 16-bit (a clock below
	 * 65.536 MHz), no 32-bit division linked. */
	uint16_t fk_up = (uint16_t)((f_cpu + 999UL) / 1000UL);
	uint16_t period = (uint16_t)((uint16_t)(fk_up - 1) / (khz ? khz : 1) + 1);
	uint16_t extra = period > 16 ? (uint16_t)(period - 16) : 0;

	for (uint8_t ps = 0; ps < 4; ps++) {
		uint8_t shift = (uint8_t)(1 + 2 * ps);
		uint16_t need = (uint16_t)((extra + (1u << shift) - 1) >> shift);
		if (need <= 255) {
			r.twbr = (uint8_t)need;
			r.twps = ps;
			break;
		}
	}
	period = (uint16_t)(16u + ((uint16_t)r.twbr << (1 + 2 * r.twps)));
	r.period = period;
	r.khz = (uint16_t)((uint16_t)(f_cpu / 1000UL) / period);
	return r;
}
