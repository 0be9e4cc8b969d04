/*
 * The system driver (UID 0x0002), always linked and the last in the
 * register order (appending it keeps every other register's number):
 *   RESET (R)      the reset causes seen since the host last cleared them
 *                  (MCUCSR's bits: PORF EXTRF BORF WDRF JTRF); a 1-byte
 *                  write clears the bits set in it
 *   FAILSAFE (R+1) link-loss timeout in ms, big-endian, 0 = off: when no
 *                  request has reached the board for that long, every
 *                  driver's safe state is applied (regmap_safe(): motors
 *                  stop, servos go limp)
 * docs/registers.md, "sys".
 */
#ifndef ORFA_SYS_H
#define ORFA_SYS_H

#include <stdint.h>

#include "firmware/regmap.h"

#define DRV_sys_NREGS 2
#define DRV_sys_REGS(X) X("RESET", 0) X("FAILSAFE", 0)

#define DRV_sys_UID 0x0002
#define DRV_sys_MAJOR 1
#define DRV_sys_MINOR 0

/* MCUCSR's reset flags, as the RESET register gives them. */
#define SYS_RESET_POWER    0x01
#define SYS_RESET_EXTERNAL 0x02
#define SYS_RESET_BROWNOUT 0x04
#define SYS_RESET_WATCHDOG 0x08
#define SYS_RESET_JTAG     0x10
#define SYS_RESET_ALL      0x1F

/* Longest FAILSAFE timeout: its ticks fit the 16-bit time base. */
#define SYS_FAILSAFE_MAX_MS 18000u

/* Once, first thing after reset: the MCU's reset flags (read before they
 * are cleared) join the causes kept over resets; a power-on starts afresh. */
void sys_boot(uint8_t reset_flags);

/* A request reached the board: the front end says so (the serial gateway
 * for every request line, the I2C slave for its own address). Cheap enough
 * for an interrupt. */
extern volatile uint8_t sys_heard;
#define SYS_HEARD() (sys_heard = 1)

/* From the front end's idle path: trips the failsafe when the link has
 * been quiet for the FAILSAFE time. While it is off (the default) this is
 * one byte test. */
void sys_poll(void);

REGMAP_DRIVER_API(sys);

#endif
