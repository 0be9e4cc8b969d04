/* Flash placement: tables live in program memory on the AVR and in ordinary
 * memory when the same code is compiled for the host (unit tests). */
#ifndef ORFA_FLASH_H
#define ORFA_FLASH_H

#ifdef __AVR__
#define ORFA_FLASH __flash
#else
#define ORFA_FLASH
#endif

#endif
