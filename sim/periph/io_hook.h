/*
 * io_hook.h: taking over an I/O register's read and write handlers in
 * simavr (avr->io[]), the one way every model here does it: outright (the
 * simulator's own USART, TWI and SPI own their registers), or chained (the
 * board model and the simavr 1.6 repairs act on a write, then let simavr's
 * handler do its part).
 */
#ifndef SIM_IO_HOOK_H
#define SIM_IO_HOOK_H

#include <stdint.h>

#include "sim_avr.h"
#include "sim_io.h"

/* The handler a register had before it was taken (w or r NULL: a plain
 * store or load of avr->data). */
typedef struct io_hook_prev_t {
	avr_io_write_t w;
	avr_io_read_t r;
	void *w_param, *r_param;
} io_hook_prev_t;

/* Own the register at data address ADDR: reads go to R, writes to W (each
 * may be NULL: the value lives in avr->data), with PARAM. */
void io_hook_take(avr_t *avr, uint16_t addr, avr_io_read_t r, avr_io_write_t w, void *param);

/* Put R and W (with PARAM; NULL: leave that handler) in front of ADDR's
 * handlers, which are kept in *PREV. */
void io_hook_chain(avr_t *avr, uint16_t addr, avr_io_read_t r, avr_io_write_t w, void *param,
		   io_hook_prev_t *prev);

/* The write as the handler kept in PREV does it (or a plain store). */
void io_hook_pass_write(avr_t *avr, const io_hook_prev_t *prev, uint16_t addr, uint8_t v);

/* The read as the handler kept in PREV does it (or a plain load). */
uint8_t io_hook_pass_read(avr_t *avr, const io_hook_prev_t *prev, uint16_t addr);

/* The write as the register's current handler does it: as the CPU would. */
void io_hook_write(avr_t *avr, uint16_t addr, uint8_t v);

/* Register IO at the END of simavr's module list, so that its reset hook
 * runs after simavr's own USART/TWI resets and has the last word on the
 * registers the simulator owns (avr_register_io puts it first). */
void io_hook_register_last(avr_t *avr, avr_io_t *io);

#endif
