/* Introspection driver (UID 0x0000), registers 0x00 and 0x01 (status). */
#ifndef ORFA_INTRO_H
#define ORFA_INTRO_H

#include "firmware/regmap.h"

#define DRV_intro_NREGS 2

extern const ORFA_FLASH drv_t drv_intro;

#endif
