/* Introspection driver (UID 0x0000), registers 0x00 and 0x01 (status). */
#ifndef ORFA_INTRO_H
#define ORFA_INTRO_H

#include "firmware/regmap.h"

#define DRV_intro_NREGS 2
#define DRV_intro_REGS(X) X("INTRO", 0) X("STATUS", 0)

#define DRV_intro_UID 0x0000
#define DRV_intro_MAJOR 1
#define DRV_intro_MINOR 0

void drv_intro_init(void);
reg_status_t drv_intro_write(uint8_t reg, const uint8_t *data, uint8_t len);
reg_status_t drv_intro_check(uint8_t reg, const uint8_t *data, uint8_t len);
uint8_t drv_intro_read(uint8_t reg, uint8_t *dst, uint8_t max);

#endif
