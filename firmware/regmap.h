/*
 * The register map: a table in flash, built at compile time from the board's
 * driver list, that routes register reads and writes to drivers
 * (docs/registers.md). Both front ends (serial gateway, I2C slave) use it.
 */
#ifndef ORFA_REGMAP_H
#define ORFA_REGMAP_H

#include <stdbool.h>
#include <stdint.h>

#include "firmware/flash.h"

/* Status register values (docs/registers.md): X(name, code, meaning). The
 * host's board map (tools/mapgen.c) takes names and meanings from here. */
#define REG_STATUS_LIST(X) \
	X(OK, 0x00, "the last operation succeeded") \
	X(BAD_LENGTH, 0x01, "the write had a length the register does not take") \
	X(BAD_VALUE, 0x02, "a value out of range (a driver number above the count, a channel that does not exist, ...)") \
	X(PIN_BUSY, 0x03, "a pin the operation needs belongs to another function") \
	X(NOT_WRITABLE, 0x04, "the register cannot be written") \
	X(NOT_READABLE, 0x05, "the register cannot be read") \
	X(READ_WRAPPED, 0x06, "introspection read past the last driver and went on with driver 1") \
	X(NOT_BOUND, 0x07, "SPI channel without a chip-select line") \
	X(NO_REGISTER, 0x08, "a write frame named a register that no driver maps") \
	X(DROPPED, 0x09, "a write frame its master abandoned was dropped, nothing of it applied")

typedef enum {
#define REG_STATUS_ENUM(name, code, text) REG_##name = code,
	REG_STATUS_LIST(REG_STATUS_ENUM)
#undef REG_STATUS_ENUM
} reg_status_t;

#define REGMAP_INTRO_REG   0x00
#define REGMAP_STATUS_REG  0x01
/* Longest read a driver is asked for at once (docs/registers.md: 64 bytes). */
#define REGMAP_READ_MAX    64

/*
 * A driver `name` (listed in ORFA_DRIVER_LIST) provides, in its header:
 *   DRV_name_UID, DRV_name_MAJOR, DRV_name_MINOR, DRV_name_NREGS
 *   REGMAP_DRIVER_API(name), which declares its four functions:
 *   drv_name_init()
 *       sets the driver up at power-on
 *   drv_name_write(reg, data, len)
 *       applies all of `data` or nothing; REG_OK or why not
 *   drv_name_check(reg, data, len)
 *       the first `len` bytes of a write still coming in, data[len - 1] just
 *       arrived: REG_OK, or why no write that starts so can be taken
 *       (whatever follows). Looks at the newest byte only, changes nothing,
 *       and is quick: a TWI slave asks it in its interrupt, to refuse the
 *       byte after (docs/registers.md, "On a slave board"). drv_name_write
 *       decides in the end.
 *   drv_name_read(reg, dst, max)
 *       puts up to `max` bytes of the register's data at `dst` and returns
 *       how many; 0 means the register cannot be read. The regmap asks again
 *       when a read frame wants more bytes than one answer gave.
 *   DRV_name_REGS(X)
 *       the register names in order, X(name, per_port): per_port 0 is one
 *       register, 1 one register per GPIO port with %c in the name standing
 *       for the port's letter (the host's board map, tools/mapgen.c)
 *   DRV_name_SAFE()
 *       a statement-like macro: the driver's link-loss safe state, applied
 *       as if the host had written it (drv_name_safe() for motors and
 *       servos), or ((void)0) for a driver that has none. Every driver
 *       says which, so none is forgotten.
 *   DRV_name_LATER()
 *       a statement-like macro, called by the main loop after each round
 *       of the front end (regmap_later()): what a write left to do once
 *       its reply is on its way (servo_hw_later(): the M32-D's edge plan),
 *       or ((void)0).
 *   DRV_name_WAIT()
 *       a statement-like macro, called with interrupts off by an interrupt
 *       that waits with them off (the M32-D slave's servo edges,
 *       drivers/servo_pins.c): a few cycles of the driver's work that
 *       must not stand still meanwhile (spi_hw_pump(): the SPI exchange's
 *       next byte), or ((void)0).
 * `reg` is the register's offset inside the driver's range.
 */
#define REGMAP_DRIVER_API(name) \
	void drv_##name##_init(void); \
	reg_status_t drv_##name##_write(uint8_t reg, const uint8_t *data, uint8_t len); \
	reg_status_t drv_##name##_check(uint8_t reg, const uint8_t *data, uint8_t len); \
	uint8_t drv_##name##_read(uint8_t reg, uint8_t *dst, uint8_t max)

/* Calls every driver's init; selects register 0x00; status OK. */
void regmap_init(void);

/* Selects a register for the following writes and reads. False if no driver
 * maps it: then no register is selected (reads give nothing, writes are
 * refused) and the status says REG_NO_REGISTER. */
bool regmap_select(uint8_t reg);

/* Whether a write of the selected register that starts with these `len`
 * bytes can still be taken, data[from..len) having arrived since the last
 * look: the driver's check (drv_name_check) at each of those lengths in
 * turn, up to the first that refuses; its reason, or REG_OK. The driver's
 * check is looked up once for all of them (the gateway hands a frame's
 * bytes in at once: ~50 cycles a byte less than a call for each). */
reg_status_t regmap_check_from(const uint8_t *data, uint8_t from, uint8_t len);

/* The newest byte alone (a TWI slave's, one at a time). */
static inline reg_status_t regmap_check(const uint8_t *data, uint8_t len)
{
	return regmap_check_from(data, (uint8_t)(len - 1), len);
}

/* Delivers one write frame's data to the selected register. */
reg_status_t regmap_write(const uint8_t *data, uint8_t len);

/* A read of the selected register begins: the status becomes OK (a read of
 * the status register leaves it as it is). */
void regmap_read_start(void);

/* One answer of the selected register: up to `max` (>= 1) bytes at `dst`,
 * how many. 0: it cannot be read (status REG_NOT_READABLE). Asking again
 * gives the driver's next answer (xact.h asks when one is used up). */
uint8_t regmap_read(uint8_t *dst, uint8_t max);

/* The link-loss failsafe tripped: every driver's DRV_name_SAFE() (motors
 * stop, servos go limp); the status register is left as it is. */
void regmap_safe(void);

/* Every driver's DRV_name_LATER(): the work a write left for the main loop
 * (main(), after each front_poll()). */
void regmap_later(void);

/* The status register's value (what reading register 0x01 gives). */
reg_status_t regmap_status(void);

/* For drivers: record a status that does not fail the operation. */
void regmap_set_status(reg_status_t status);

/* Number of drivers, introspection included. */
uint8_t regmap_driver_count(void);

#define REGMAP_RECORD_LEN 6

/* The first `len` (<= 6) bytes of driver n's record (n 1-based):
 * [UID hi][UID lo][major][minor][start][count]. */
void regmap_driver_record(uint8_t n, uint8_t *dst, uint8_t len);

#endif
