/* Introspection driver (UID 0x0000), registers 0x00 and 0x01 (status). */
#ifndef ORFA_INTRO_H
#define ORFA_INTRO_H

#include "firmware/regmap.h"

#define DRV_intro_NREGS 2
#define DRV_intro_REGS(X) X("INTRO", 0) X("STATUS", 0)

#define DRV_intro_UID 0x0000
#define DRV_intro_MAJOR 1
#define DRV_intro_MINOR 0

REGMAP_DRIVER_API(intro);

#endif
