/* Memory placement: tables live in program memory on the AVR and in ordinary
 * memory when the same code is compiled for the host (unit tests); ORFA_NOINIT
 * data keep their SRAM over a reset (avr-libc's .noinit: not cleared at
 * start-up), plain variables on the host. */
#ifndef ORFA_FLASH_H
#define ORFA_FLASH_H

#ifdef __AVR__
#define ORFA_FLASH __flash
#define ORFA_NOINIT __attribute__((section(".noinit")))
#else
#define ORFA_FLASH
#define ORFA_NOINIT
#endif

#endif
