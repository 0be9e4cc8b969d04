/* GPIO driver (docs/registers.md, "GPIO"): UID from the board (0x0020 M32-D, 0x0021
 * M128-S), N ports: registers R..R+N-1 values, R+N..R+2N-1 modes. */
#ifndef DRV_GPIO_H
#define DRV_GPIO_H

#include "board.h"
#include "firmware/regmap.h"

#define GPIO_COUNT_PORT(letter) + 1
#define GPIO_NPORTS (0 BOARD_GPIO_PORTS(GPIO_COUNT_PORT))
#define DRV_gpio_NREGS (2 * GPIO_NPORTS)
#define DRV_gpio_REGS(X) X("VALUE_%c", 1) X("MODE_%c", 1)

#define DRV_gpio_UID BOARD_GPIO_UID
#define DRV_gpio_MAJOR 1
#define DRV_gpio_MINOR 1
/* The link-loss failsafe leaves it as it is. */
#define DRV_gpio_SAFE() ((void)0)
#define DRV_gpio_LATER() ((void)0)
#define DRV_gpio_WAIT() ((void)0)

REGMAP_DRIVER_API(gpio);

#endif
