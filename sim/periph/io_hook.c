/*
 * io_hook.c: taking over I/O register handlers (io_hook.h).
 */
#include <stddef.h>

#include "periph/io_hook.h"

void io_hook_take(avr_t *avr, uint16_t addr, avr_io_read_t r, avr_io_write_t w, void *param)
{
	avr_io_addr_t io = AVR_DATA_TO_IO(addr);

	avr->io[io].r.c = r;
	avr->io[io].r.param = r ? param : NULL;
	avr->io[io].w.c = w;
	avr->io[io].w.param = w ? param : NULL;
}

void io_hook_chain(avr_t *avr, uint16_t addr, avr_io_read_t r, avr_io_write_t w, void *param,
		   io_hook_prev_t *prev)
{
	avr_io_addr_t io = AVR_DATA_TO_IO(addr);

	prev->r = avr->io[io].r.c;
	prev->r_param = avr->io[io].r.param;
	prev->w = avr->io[io].w.c;
	prev->w_param = avr->io[io].w.param;
	if (r) {
		avr->io[io].r.c = r;
		avr->io[io].r.param = param;
	}
	if (w) {
		avr->io[io].w.c = w;
		avr->io[io].w.param = param;
	}
}

void io_hook_pass_write(avr_t *avr, const io_hook_prev_t *prev, uint16_t addr, uint8_t v)
{
	if (prev->w) {
		prev->w(avr, addr, v, prev->w_param);
	} else {
		avr->data[addr] = v;
	}
}

uint8_t io_hook_pass_read(avr_t *avr, const io_hook_prev_t *prev, uint16_t addr)
{
	return prev->r ? prev->r(avr, addr, prev->r_param) : avr->data[addr];
}

void io_hook_write(avr_t *avr, uint16_t addr, uint8_t v)
{
	avr_io_addr_t io = AVR_DATA_TO_IO(addr);

	if (avr->io[io].w.c) {
		avr->io[io].w.c(avr, addr, v, avr->io[io].w.param);
	} else {
		avr->data[addr] = v;
	}
}

void io_hook_register_last(avr_t *avr, avr_io_t *io)
{
	avr_io_t **link = &avr->io_port;

	while (*link) {
		link = &(*link)->next;
	}
	io->next = NULL;
	io->avr = avr;
	*link = io;
}
