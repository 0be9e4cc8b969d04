/* RC servo driver (docs/registers.md, "Servos"): registers RS (compatibility) and SP. */
#ifndef DRV_SERVO_H
#define DRV_SERVO_H

#include "board.h"
#include "firmware/regmap.h"

#define DRV_servo_NREGS 2
#define DRV_servo_REGS(X) X("RS", 0) X("SP", 0)
#define SERVO_CHANNELS BOARD_SERVO_CHANNELS
#define SERVO_MIN_US 500
#define SERVO_MAX_US 2500
#define SERVO_MAX_TRIPLES 16

#define DRV_servo_UID BOARD_SERVO_UID
#define DRV_servo_MAJOR 2
#define DRV_servo_MINOR 0
/* The link-loss failsafe turns every channel off (limp). */
#define DRV_servo_SAFE() drv_servo_safe()
#define DRV_servo_WAIT() ((void)0)
#define DRV_servo_LATER() drv_servo_later()

REGMAP_DRIVER_API(servo);
/* Every channel's width 0 (no pulses, line low), as a host's writes of
 * [ch][00][00] for each would. */
void drv_servo_safe(void);
/* What a write left for later, with the widths it set: servo_hw_later(). */
void drv_servo_later(void);

#endif
