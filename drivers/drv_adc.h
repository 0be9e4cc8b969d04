/* ADC driver (UID 0x0040): RC (settings, channel mask), RD (results). */
#ifndef DRV_ADC_H
#define DRV_ADC_H

#include "firmware/regmap.h"

#define DRV_adc_NREGS 2
#define DRV_adc_REGS(X) X("RC", 0) X("RD", 0)

/* Settings byte of RC. */
#define ADC_SET_REF_MASK 0x03  /* 00 AREF, 01 AVCC, 10/11 internal 2.56 V */
#define ADC_SET_10BIT    0x04  /* else 8-bit results */

#define DRV_adc_UID 0x0040
#define DRV_adc_MAJOR 1
#define DRV_adc_MINOR 1
/* The link-loss failsafe leaves it as it is. */
#define DRV_adc_SAFE() ((void)0)
#define DRV_adc_LATER() ((void)0)
#define DRV_adc_WAIT() ((void)0)

REGMAP_DRIVER_API(adc);

#endif
