/*
 * Port registers by port index (0 = port A): the only way drivers touch
 * pins. Every write is an atomic read-modify-write, so an interrupt that
 * drives other lines of the same port (servo pulses) never sees its lines
 * overwritten with stale values. The AVR version is port_io_avr.c; unit
 * tests link a fake.
 */
#ifndef ORFA_PORT_IO_H
#define ORFA_PORT_IO_H

#include <stdint.h>

/* PORTx lines in `mask` := value (outputs: level; inputs: pull-up). */
void port_io_write(uint8_t port, uint8_t mask, uint8_t value);
/* DDRx lines in `mask` := value (1 = output). */
void port_io_dir(uint8_t port, uint8_t mask, uint8_t value);
/* PINx: the levels on the pins. */
uint8_t port_io_pins(uint8_t port);
/* PORTx and DDRx as set. */
uint8_t port_io_out(uint8_t port);
uint8_t port_io_dirs(uint8_t port);

#endif
