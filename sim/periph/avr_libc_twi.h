/*
 * avr_libc_twi.h: avr-libc's TWI status codes (TW_START .. TW_NO_INFO) for
 * the host build, from avr-libc's own <util/twi.h> (found on the
 * -idirafter path the Makefile adds). That header includes <avr/io.h>,
 * which needs an AVR target: its guard is set so the include does nothing,
 * and only the TW_* values, plain numbers, are used.
 */
#ifndef SIM_AVR_LIBC_TWI_H
#define SIM_AVR_LIBC_TWI_H

#ifndef _AVR_IO_H_
#define _AVR_IO_H_
#define SIM_AVR_IO_H_SKIPPED
#endif

#include <util/twi.h>

#ifdef SIM_AVR_IO_H_SKIPPED
#undef _AVR_IO_H_
#undef SIM_AVR_IO_H_SKIPPED
#endif

#endif
