/* DC motor driver (UID 0x0060, M32-D): PWM1, PWM2, DIR1, DIR2. */
#ifndef DRV_MOTOR_H
#define DRV_MOTOR_H

#include "firmware/regmap.h"

#define DRV_motor_NREGS 4

extern const ORFA_FLASH drv_t drv_motor;

#endif
