#include "drivers/drv_adc.h"

#include "board.h"
#include "drivers/adc_hw.h"
#include "firmware/pins.h"
#include "firmware/port_io.h"

#define ADC_REG_RC 0
#define ADC_REG_RD 1
#define ADC_PORT ((uint8_t)(BOARD_ADC_PORT - 'A'))
#define ADC_PIN0 PIN_ID(BOARD_ADC_PORT, 0)  /* channel 0's pin; channel n is line n */

static struct {
	uint8_t settings;
	uint8_t mask;
} adc_cfg;

/* What a write's bytes so far rule out (regmap.h): refused at once. */
reg_status_t drv_adc_check(uint8_t reg, const uint8_t *data, uint8_t len)
{
	(void)data;
	if (reg != ADC_REG_RC) {
		return REG_NOT_WRITABLE;
	}
	return len > 2 ? REG_BAD_LENGTH : REG_OK;  /* settings, mask */
}

/* RC: [settings][mask], always both. Enabled channels take their pins
 * (input, no pull-up); all of the write or none of it. */
reg_status_t drv_adc_write(uint8_t reg, const uint8_t *data, uint8_t len)
{
	if (reg != ADC_REG_RC) {
		return REG_NOT_WRITABLE;
	}
	if (len != 2) {
		return REG_BAD_LENGTH;
	}
	uint8_t settings = data[0];
	uint8_t mask = data[1];
	if (settings & (uint8_t)~(ADC_SET_REF_MASK | ADC_SET_10BIT)) {
		return REG_BAD_VALUE;
	}
	uint8_t taking = mask & (uint8_t)~adc_cfg.mask;
	/* Check every line before taking any: giving a taken line back would
	 * reset it to an input, though it may have been a GPIO output. (The
	 * masks are walked a bit at a time: a shift by the channel's number
	 * is a loop on the AVR.) */
	uint8_t lines = taking;
	for (uint8_t pin = ADC_PIN0; lines; pin++, lines >>= 1) {
		if ((lines & 1) && !pins_can_claim(pin, PIN_ADC)) {
			return REG_PIN_BUSY;
		}
	}
	uint8_t giving = adc_cfg.mask & (uint8_t)~mask;
	lines = taking;
	for (uint8_t pin = ADC_PIN0; lines | giving; pin++, lines >>= 1, giving >>= 1) {
		if (lines & 1) {
			pins_claim(pin, PIN_ADC);
		} else if (giving & 1) {
			pins_release(pin, PIN_ADC);
		}
	}
	port_io_dir(ADC_PORT, taking, 0);
	port_io_write(ADC_PORT, taking, 0);
	uint8_t ref = settings & ADC_SET_REF_MASK;
	adc_hw_config(ref >= 2 ? 3 : ref, mask);
	adc_cfg.settings = settings;
	adc_cfg.mask = mask;
	return REG_OK;
}

/* RC reads back [settings][mask]; RD gives channels 0..7, one byte each
 * (8-bit) or two, big-endian (10-bit); channels off read 0. */
uint8_t drv_adc_read(uint8_t reg, uint8_t *dst, uint8_t max)
{
	uint8_t n = 0;
	if (reg == ADC_REG_RC) {
		dst[n++] = adc_cfg.settings;
		if (n < max) {
			dst[n++] = adc_cfg.mask;
		}
		return n;
	}
	for (uint8_t ch = 0; ch < 8 && n < max; ch++) {
		uint16_t v = adc_hw_value(ch);
		if (adc_cfg.settings & ADC_SET_10BIT) {
			dst[n++] = (uint8_t)(v >> 8);
			if (n == max) {
				break;
			}
			dst[n++] = (uint8_t)v;
		} else {
			dst[n++] = (uint8_t)(v >> 2);
		}
	}
	return n;
}

void drv_adc_init(void)
{
	adc_cfg.settings = 0;
	adc_cfg.mask = 0;
	adc_hw_config(0, 0);
}
