/* Host fakes for the unit tests: a bus with devices, a test driver, the
 * reply sink. */
#ifndef UNIT_FAKES_H
#define UNIT_FAKES_H

#include <stdint.h>

#include "firmware/regmap.h"

/* The test driver "fake": 3 registers.
 *   +0: write 1..4 bytes (stored), read gives them back; 0 bytes rejected
 *   +1: read-only, gives 3 bytes 0x11 0x22 0x33 per answer
 *   +2: write-only, any length */
#define DRV_fake_NREGS 3
#define DRV_fake_UID 0x0F0F
#define DRV_fake_MAJOR 2
#define DRV_fake_MINOR 3
REGMAP_DRIVER_API(fake);
/* Its link-loss safe state: counts the calls. */
#define DRV_fake_SAFE() drv_fake_safe()
void drv_fake_safe(void);
#define DRV_fake_LATER() ((void)0)
extern unsigned fake_safe_calls;
/* The time base's count (firmware/clock.h), set by the tests. */
extern volatile uint16_t clock_wraps;
#define fake_clock clock_wraps

/* Everything the fake bus saw, as text: "S A0+ W00+ R11+ R22- P ". */
extern char bus_log[4096];
/* Fake 24C02 at 0xA0. */
extern uint8_t eeprom[256];
/* Reply characters sent by the executor. */
extern char out_buf[65536];
extern unsigned out_len;

void fakes_reset(void);

#endif
