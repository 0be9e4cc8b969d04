/*
 * mcp3008.c: MCP3008-like SPI ADC, bit level.
 */
#include <stdio.h>
#include <string.h>

#include "parts/mcp3008.h"
#include "parts/part.h"

static void mcp_select(spi_dev_t *d, uint64_t cycle)
{
	mcp3008_t *m = (mcp3008_t *)d;

	(void)cycle;
	m->state = 0;
	m->config = 0;
	m->out_n = 0;
}

static void mcp_deselect(spi_dev_t *d, uint64_t cycle)
{
	(void)d;
	(void)cycle;
}

static uint16_t mcp_convert(const mcp3008_t *m)
{
	int sgl = (m->config >> 3) & 1, ch = m->config & 7;
	int64_t vin = m->mv[ch];
	uint32_t vref = *m->vref ? *m->vref : 1;

	if (!sgl) {
		/* pairs: CH0-CH1, CH1-CH0, CH2-CH3, ... */
		vin = (int64_t)m->mv[ch] - (int64_t)m->mv[ch ^ 1];
		if (vin < 0) {
			vin = 0;
		}
	}
	int64_t code = vin * 1024 / vref;

	return (uint16_t)(code > 1023 ? 1023 : code);
}

static void mcp_in(spi_dev_t *d, int bit, uint64_t cycle)
{
	mcp3008_t *m = (mcp3008_t *)d;

	(void)cycle;
	if (m->state == 0) {
		if (bit) {
			m->state = 1;
		}
	} else if (m->state <= 4) {
		m->config = (uint8_t)((m->config << 1) | bit);
		if (++m->state == 5) {
			m->code = mcp_convert(m);
			m->last_code = m->code;
		}
	} else if (m->state == 5) {
		m->state = 6;	/* the sample clock */
	}
}

static int mcp_out(spi_dev_t *d)
{
	mcp3008_t *m = (mcp3008_t *)d;

	if (m->state < 6) {
		return 1;	/* undriven */
	}
	int k = m->out_n++;

	if (k == 0) {
		return 0;	/* null bit */
	}
	if (k <= 10) {
		return (m->code >> (10 - k)) & 1;	/* B9..B0 */
	}
	if (k <= 19) {
		return (m->code >> (k - 10)) & 1;	/* B1..B9 */
	}
	return 0;
}

static int mcp_dump(spi_dev_t *d, char *buf, int size)
{
	mcp3008_t *m = (mcp3008_t *)d;
	int n = snprintf(buf, (size_t)size, "last %d vref %u mv", m->last_code, *m->vref);

	for (int i = 0; i < 8 && n < size; i++) {
		n += snprintf(buf + n, (size_t)(size - n), " %u", m->mv[i]);
	}
	return n;
}

/* --- descriptor ------------------------------------------------------------ */

/* Converting the board's analog inputs against its AVCC (ENV). */
static void mcp3008_init(void *self, const part_env_t *env)
{
	mcp3008_t *m = self;

	m->dev.select = mcp_select;
	m->dev.deselect = mcp_deselect;
	m->dev.in_bit = mcp_in;
	m->dev.next_out = mcp_out;
	m->dev.dump = mcp_dump;
	m->mv = env->adc_mv;
	m->vref = env->avcc;
	m->last_code = -1;
}

const part_kind_t mcp3008_kind = {
	.name = "mcp3008",
	.attach = PART_SPI,
	.options = "",
	.about = "an 8-channel 10-bit SPI ADC like an MCP3008 (the board's analog inputs)",
	.size = sizeof(mcp3008_t),
	.init = mcp3008_init,
};
