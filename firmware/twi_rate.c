#include "firmware/twi_rate.h"

twi_rate_t twi_rate_for_khz(uint32_t f_cpu, uint16_t khz)
{
	twi_rate_t r;

	/* The shortest SCL period not faster than asked, then the smallest
	 * prescaler whose TWBR reaches it: TWBR = ceil((period - 16) / 2·4^ps)
	 * (ceil of the whole period first changes nothing: ceil(ceil(y)/d) =
	 * ceil(y/d)). The same rule, and floor's, take the clock to kHz
	 * first, a constant: the divisions left are 16-bit (a clock below
	 * 65.536 MHz), no 32-bit division linked. */
	uint16_t fk_up = (uint16_t)((f_cpu + 999UL) / 1000UL);
	uint16_t period = (uint16_t)((uint16_t)(fk_up - 1) / (khz ? khz : 1) + 1);
	uint16_t extra = period > 16 ? (uint16_t)(period - 16) : 0;

	/* ceil(extra / 2·4^ps) a prescaler step at a time: ceil(ceil(x / a)
	 * / b) = ceil(x / ab), so each step divides the last one's by 4. */
	uint16_t need = (uint16_t)((extra + 1) >> 1);
	uint16_t unit = 2;  /* 2·4^ps */
	uint8_t ps = 0;
	while (need > 255 && ps < 3) {
		need = (uint16_t)((need + 3) >> 2);
		unit = (uint16_t)(unit << 2);
		ps++;
	}
	/* the slowest rate when even the largest prescaler falls short */
	r.twbr = need > 255 ? 255 : (uint8_t)need;
	r.twps = ps;
	period = (uint16_t)(16u + r.twbr * unit);
	r.period = period;
	r.khz = (uint16_t)((uint16_t)(f_cpu / 1000UL) / period);
	return r;
}
