/*
 * The MCU layer: the only place that knows how ATmega32 and ATmega128 name
 * their registers. Drivers and front ends use these names, never #ifdefs.
 */
#ifndef ORFA_MCU_H
#define ORFA_MCU_H

#include <avr/io.h>
#include <stdint.h>

#include "board.h"

#define MCU_CAT3_(a, b, c) a##b##c
#define MCU_CAT3(a, b, c)  MCU_CAT3_(a, b, c)

/* The time base's 8-bit timer (the board file's BOARD_CLOCK_TIMER): the
 * same register and bit names on both MCUs, clk/8 = CSn1 on both. */
#define MCU_CLOCK_TCCR     MCU_CAT3(TCCR, BOARD_CLOCK_TIMER, )
#define MCU_CLOCK_CLK8     _BV(MCU_CAT3(CS, BOARD_CLOCK_TIMER, 1))
#define MCU_CLOCK_TOIE     _BV(MCU_CAT3(TOIE, BOARD_CLOCK_TIMER, ))
#define MCU_CLOCK_OCIE     _BV(MCU_CAT3(OCIE, BOARD_CLOCK_TIMER, ))
#define MCU_CLOCK_OCF      _BV(MCU_CAT3(OCF, BOARD_CLOCK_TIMER, ))
#define MCU_CLOCK_OCR      MCU_CAT3(OCR, BOARD_CLOCK_TIMER, )
#define MCU_CLOCK_TCNT     MCU_CAT3(TCNT, BOARD_CLOCK_TIMER, )
#define MCU_CLOCK_OVF_vect MCU_CAT3(TIMER, BOARD_CLOCK_TIMER, _OVF_vect)

#if defined(__AVR_ATmega32__)
#define MCU_UDR            UDR
#define MCU_UCSRA          UCSRA
#define MCU_UCSRB          UCSRB
#define MCU_UBRRL          UBRRL
#define MCU_UBRRH          UBRRH
#define MCU_UART_RX_vect   USART_RXC_vect
#define MCU_UART_UDRE_vect USART_UDRE_vect
#define MCU_RESET_FLAGS    MCUCSR
#elif defined(__AVR_ATmega128__)
/* Two USARTs: the board file's BOARD_UART picks the PC's. */
#define MCU_UDR            MCU_CAT3(UDR, BOARD_UART, )
#define MCU_UCSRA          MCU_CAT3(UCSR, BOARD_UART, A)
#define MCU_UCSRB          MCU_CAT3(UCSR, BOARD_UART, B)
#define MCU_UBRRL          MCU_CAT3(UBRR, BOARD_UART, L)
#define MCU_UBRRH          MCU_CAT3(UBRR, BOARD_UART, H)
#define MCU_UART_RX_vect   MCU_CAT3(USART, BOARD_UART, _RX_vect)
#define MCU_UART_UDRE_vect MCU_CAT3(USART, BOARD_UART, _UDRE_vect)
#define MCU_RESET_FLAGS    MCUCSR
#else
#error "ORFA supports ATmega32 and ATmega128"
#endif

/* The MCU's I/O ports in letter order from A, X(letter). */
#if defined(__AVR_ATmega128__)
#define MCU_PORT_LETTERS(X) X(A) X(B) X(C) X(D) X(E) X(F) X(G)
#else
#define MCU_PORT_LETTERS(X) X(A) X(B) X(C) X(D)
#endif

/* The three registers of one I/O port. */
typedef struct {
	volatile uint8_t *pin;
	volatile uint8_t *ddr;
	volatile uint8_t *port;
} mcu_port_t;

/* The registers of port `index` (0 = port A). The MCU's ports only: the
 * board files name nothing else. */
mcu_port_t mcu_port(uint8_t index);

/* The same for an `index` known when compiling: the compiler folds it to
 * the registers themselves (a bit of them is one sbi/cbi), no table read.
 * A variable index would inline every test: use mcu_port() then. */
static inline __attribute__((always_inline)) mcu_port_t mcu_port_at(uint8_t index)
{
#define MCU_PORT_IF(letter) \
	if (index == (uint8_t)(*#letter - 'A')) { \
		return (mcu_port_t){ &PIN##letter, &DDR##letter, &PORT##letter }; \
	}
	MCU_PORT_LETTERS(MCU_PORT_IF)
#undef MCU_PORT_IF
	return (mcu_port_t){ 0, 0, 0 };
}

/* Watchdog on (250 ms), reset flags cleared (simavr re-arms a fired
 * watchdog until WDRF is cleared; harmless on silicon). Returns the reset
 * flags as they were, so the reset cause is not lost (firmware/sys.h). */
uint8_t mcu_watchdog_start(void);

/* Frees the JTAG pins (M32-D PC2-PC5, M128-S PF4-PF7) for their board
 * functions even when the JTAGEN fuse is programmed. */
void mcu_jtag_off(void);

#endif
