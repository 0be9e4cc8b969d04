/*
 * OR-AVR-M32-D: ATmega32 at 7.3728 MHz.
 *
 * Pin map (SPEC section 1, reference wiring of the original board):
 *
 *   port  7     6     5     4     3     2     1     0
 *   A     S7    S6    S5    S4    S3    S2    S1    S0     servo 0-7 / ADC 7-0
 *   B     SCK   MISO  MOSI  SS    S12   S13   DIR2  DIR1   SPI, servos, motor dir
 *   C     S8    S9    S10   S11   -     -     SDA   SCL    servos, TWI
 *   D     -     -     PWM1  PWM2  -     -     TXD   RXD    motor PWM (= S14/S15), UART
 *
 * This header is data only: the firmware and the simulator's board model both
 * read it, so it must not depend on avr-libc.
 */
#ifndef BOARD_M32D_H
#define BOARD_M32D_H

#define BOARD_NAME      "OR-AVR-M32-D"
#define BOARD_ID        "m32d"
#define BOARD_MCU_NAME  "atmega32"
#define BOARD_CLOCK_HZ  7372800UL

/* The gateway's serial port and the TWI pins. */
#define BOARD_UART      0
#define BOARD_TWI_PORT  'C'
#define BOARD_TWI_SCL   0
#define BOARD_TWI_SDA   1

/*
 * Every pin with a fixed function: X(port, bit, function, index).
 * Functions: UART_RX, UART_TX, TWI_SCL, TWI_SDA.
 */
#define BOARD_PINS(X) \
	X('D', 0, UART_RX, 0) \
	X('D', 1, UART_TX, 0) \
	X('C', 0, TWI_SCL, 0) \
	X('C', 1, TWI_SDA, 0)

#endif
