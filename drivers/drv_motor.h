/* DC motor driver (UID 0x0060, M32-D): PWM1, PWM2, DIR1, DIR2. */
#ifndef DRV_MOTOR_H
#define DRV_MOTOR_H

#include "firmware/regmap.h"

#define DRV_motor_NREGS 4
#define DRV_motor_REGS(X) X("PWM1", 0) X("PWM2", 0) X("DIR1", 0) X("DIR2", 0)

#define DRV_motor_UID 0x0060
#define DRV_motor_MAJOR 1
#define DRV_motor_MINOR 1
/* The link-loss failsafe stops both motors. */
#define DRV_motor_SAFE() drv_motor_safe()
#define DRV_motor_LATER() ((void)0)
#define DRV_motor_WAIT() ((void)0)

REGMAP_DRIVER_API(motor);
/* PWM1 and PWM2 0, as a host's write of 00 00 to PWM1 (directions kept). */
void drv_motor_safe(void);

#endif
