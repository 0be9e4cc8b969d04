/* ADC conversions in the background: single conversions restarted from the
 * ADC interrupt over the enabled channels (simavr 1.6 does not model
 * free-running mode; silicon is happy either way). */
#ifndef ADC_HW_H
#define ADC_HW_H

#include <stdint.h>

/* Reference selection as the ADMUX REFS bits: 0 AREF, 1 AVCC, 3 internal. */
void adc_hw_config(uint8_t refs, uint8_t mask);

/* The latest 10-bit result of channel `ch` (0 until it has one). */
uint16_t adc_hw_value(uint8_t ch);

#endif
