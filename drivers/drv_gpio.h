/* GPIO driver (SPEC section 3): UID from the board (0x0020 M32-D, 0x0021
 * M128-S), N ports: registers R..R+N-1 values, R+N..R+2N-1 modes. */
#ifndef DRV_GPIO_H
#define DRV_GPIO_H

#include "board.h"
#include "firmware/regmap.h"

#define GPIO_COUNT_PORT(letter) + 1
#define GPIO_NPORTS (0 BOARD_GPIO_PORTS(GPIO_COUNT_PORT))
#define DRV_gpio_NREGS (2 * GPIO_NPORTS)

extern const ORFA_FLASH drv_t drv_gpio;

#endif
