/*
 * Every driver's header. The build picks which ones are linked with
 * ORFA_DRIVER_LIST, an X-macro list made by the Makefile from DRIVERS
 * (for example `X(gpio) X(spi)`), in register order.
 */
#ifndef ORFA_DRIVERS_H
#define ORFA_DRIVERS_H

#include "drivers/drv_adc.h"
#include "drivers/drv_gpio.h"
#include "drivers/drv_motor.h"
#include "drivers/drv_servo.h"
#include "drivers/drv_spi.h"
#include "firmware/intro.h"

#ifndef ORFA_DRIVER_LIST
#define ORFA_DRIVER_LIST
#endif

#endif
