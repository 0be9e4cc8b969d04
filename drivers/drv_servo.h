/* RC servo driver (SPEC section 3): registers RS (compatibility) and SP. */
#ifndef DRV_SERVO_H
#define DRV_SERVO_H

#include "board.h"
#include "firmware/regmap.h"

#define DRV_servo_NREGS 2
#define SERVO_CHANNELS BOARD_SERVO_CHANNELS
#define SERVO_MIN_US 500
#define SERVO_MAX_US 2500
#define SERVO_MAX_TRIPLES 16

extern const ORFA_FLASH drv_t drv_servo;

#endif
