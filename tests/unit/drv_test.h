/*
 * Driver unit tests: the real drivers, register map, pin table and board
 * pin map of one board, over hw_fakes.c, driven through the regmap API the
 * way the front ends drive it. Register numbers and expected bytes come
 * from docs/registers.md, not from the code under test.
 */
#ifndef UNIT_DRV_TEST_H
#define UNIT_DRV_TEST_H

#include <stdint.h>

#include "board.h"
#include "firmware/pins.h"
#include "firmware/regmap.h"
#include "hw_fakes.h"

/* The board's register map as docs/registers.md gives it. */
typedef struct {
	const char *name;
	uint8_t nregs;          /* registers in all (first unmapped register) */
	uint8_t ndrivers;       /* introspection included */
	const char *intro;      /* every record, hex, in order */
	uint8_t gpio_nports;
	uint8_t gpio_value;     /* value register of the first GPIO port */
	uint8_t gpio_mode;      /* mode register of the first GPIO port */
	uint8_t gpio_port[4];   /* GPIO ports in register order, port_io index */
	uint8_t spi_data, spi_config;
	uint8_t adc_rc, adc_rd;
	uint8_t adc_port;       /* port_io index of the ADC port */
	uint8_t adc_gpio;       /* its number among the GPIO ports */
	uint8_t servo_rs, servo_sp;
	uint8_t servo_channels;
} board_t;

extern const board_t B;

/* Each board's own tests (test_drv_<board>.c). */
void board_tests(void);

/* The transaction module with these drivers (test_xact.c). */
void xact_tests(void);

/* Power-on: fakes reset, pins_init(), regmap_init() as main() does. */
void boot(void);

void check_at(const char *file, int line, int ok, const char *what);
void check_eq_at(const char *file, int line, long got, long want, const char *what);
/* Selects `reg`, writes the bytes of `hex` ("80 60 00 01"), expects the
 * write's result and the status register to be `status`. */
void write_at(const char *file, int line, uint8_t reg, const char *hex, reg_status_t status);
/* Selects `reg`, reads n bytes, expects `hex` and then status `status`. */
void read_at(const char *file, int line, uint8_t reg, uint8_t n, const char *hex,
	     reg_status_t status);
/* Selects `reg`, reads n bytes: refused (status 05), nothing filled. */
void unreadable_at(const char *file, int line, uint8_t reg, uint8_t n);

#define CHECK(cond) check_at(__FILE__, __LINE__, (cond), #cond)
#define CHECK_EQ(got, want) check_eq_at(__FILE__, __LINE__, (long)(got), (long)(want), #got)
#define WRITE(reg, hex, status) write_at(__FILE__, __LINE__, (reg), (hex), (status))
#define READ(reg, n, hex) read_at(__FILE__, __LINE__, (reg), (n), (hex), REG_OK)
#define READ_ST(reg, n, hex, st) read_at(__FILE__, __LINE__, (reg), (n), (hex), (st))
#define UNREADABLE(reg, n) unreadable_at(__FILE__, __LINE__, (reg), (n))

/* Everything a rejected write must leave as it was: ports, pin owners,
 * hardware records and every readable register's bytes. */
typedef struct {
	uint8_t out[BOARD_NPORTS], ddr[BOARD_NPORTS];
	uint8_t owner[BOARD_NPORTS * 8];
	hw_rec_t hw;
	uint8_t regs[256][64];
	uint8_t readable[256];
} snap_t;

void snap_take(snap_t *s);
void same_at(const char *file, int line, const snap_t *before);
#define SAME(before) same_at(__FILE__, __LINE__, (before))

/* Writes each of the hex strings (a NULL-ended list) to `reg`: every one
 * is refused with `status` and leaves everything as it was. */
void refused_writes_at(const char *file, int line, uint8_t reg, reg_status_t status,
		       const char *const *hex);
#define REFUSED(reg, status, ...) \
	refused_writes_at(__FILE__, __LINE__, (reg), (status), (const char *const[]){ __VA_ARGS__, NULL })

/* Pin id of port index p, line l. */
#define PIN(p, l) ((uint8_t)((p) * 8 + (l)))

#endif
