/*
 * OR-AVR-M128-S: ATmega128 at 7.3728 MHz.
 *
 * Pin map (SPEC section 1):
 *
 *   port  7     6     5     4     3     2     1     0
 *   A     IO7   IO6   IO5   IO4   IO3   IO2   IO1   IO0    GPIO port A
 *   B     OC1C  -     -     -     MISO  MOSI  SCK   SS     SPI, counter 3 clock
 *   D     -     -     -     -     -     -     SDA   SCL    TWI
 *   E     -     -     OC3C  OC3B  OC3A  -     TXD0  RXD0   counter 0-2 clocks, UART0
 *   F     ADC7  ADC6  ADC5  ADC4  ADC3  ADC2  ADC1  ADC0   GPIO port F / ADC
 *
 * This header is data only: the firmware and the simulator's board model both
 * read it, so it must not depend on avr-libc.
 */
#ifndef BOARD_M128S_H
#define BOARD_M128S_H

#define BOARD_NAME      "OR-AVR-M128-S"
#define BOARD_ID        "m128s"
#define BOARD_MCU_NAME  "atmega128"
#define BOARD_CLOCK_HZ  7372800UL

/* The gateway's serial port (USART0) and the TWI pins. */
#define BOARD_UART      0
#define BOARD_TWI_PORT  'D'
#define BOARD_TWI_SCL   0
#define BOARD_TWI_SDA   1

/*
 * Every pin with a fixed function: X(port, bit, function, index).
 * Functions: UART_RX, UART_TX, TWI_SCL, TWI_SDA.
 */
#define BOARD_PINS(X) \
	X('E', 0, UART_RX, 0) \
	X('E', 1, UART_TX, 0) \
	X('D', 0, TWI_SCL, 0) \
	X('D', 1, TWI_SDA, 0)

#endif
