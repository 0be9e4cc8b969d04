/*
 * OR-AVR-M128-S: ATmega128 at 7.3728 MHz.
 *
 * Pin map (docs/boards.md, docs/board-m128s.md):
 *
 *   port  7     6     5     4     3     2     1     0
 *   A     IO7   IO6   IO5   IO4   IO3   IO2   IO1   IO0    GPIO port A
 *   B     CLK3  -     -     -     MISO  MOSI  SCK   SS     SPI, servo counter 3 clock (OC1C)
 *   D     -     -     -     -     TXD1  RXD1  SDA   SCL    UART1 (the PC), TWI
 *   E     -     RST   CLK2  CLK1  CLK0  -     -     -      counter clocks (OC3A-C), reset
 *   F     AD7   AD6   AD5   AD4   AD3   AD2   AD1   AD0    GPIO port F = ADC (JTAG switched off)
 *
 * Servos: 32 channels through four CD4017 decade counters. Counter c is
 * clocked by CLKc, all four share the reset line RST. Channel n is output
 * Q(1 + n % 8) of counter n / 8; Q0 and Q9 are idle states.
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
#define BOARD_NPORTS    7   /* A..G */

/* The PC's serial port: USART1, as ORFA 0.7.5 (PE0/PE1 of USART0 are the
 * ISP programming pins), and the TWI pins. */
#define BOARD_UART      1
/* USART1's receive interrupt (vector 30) is outranked by the clock's, the
 * ADC's and the servo counters' interrupts, and back to back those keep it
 * waiting longer than the USART holds characters at 460800 (320 cycles):
 * the ones with no deadline of their own let it in (FRONT_ISR_LETS_RX,
 * firmware/front.h). */
#define BOARD_RX_OUTRANKED 1
#define BOARD_TWI_PORT  'D'
#define BOARD_TWI_SCL   0
#define BOARD_TWI_SDA   1

/* The time base (firmware/clock.c): Timer0 at clk/8 (the servo counters
 * run on Timer1 and Timer3). */
#define BOARD_CLOCK_TIMER 0

/* GPIO driver (UID 0x0021): its ports, in register order. */
#define BOARD_GPIO_UID  0x0021
#define BOARD_GPIO_PORTS(X) X('A') X('F')

/* ADC: the port whose lines are ADC channels 0-7. */
#define BOARD_ADC_PORT  'F'

/* Servo driver (UID 0x0030): 32 channels on four CD4017 counters. */
#define BOARD_SERVO_UID 0x0030
#define BOARD_SERVO_CHANNELS 32
#define BOARD_SERVO_COUNTERS 4
#define BOARD_SERVO_PER_COUNTER 8

/*
 * Fixed wiring: X(port, bit, function, index).
 *   UART_RX/UART_TX, TWI_SCL/TWI_SDA, SPI_SS/SPI_MOSI/SPI_MISO/SPI_SCK,
 *   SERVO_CLK c (clock of counter c), SERVO_RST (the counters' common reset).
 */
#define BOARD_PINS(X) \
	X('D', 2, UART_RX, 0) \
	X('D', 3, UART_TX, 0) \
	X('D', 0, TWI_SCL, 0) \
	X('D', 1, TWI_SDA, 0) \
	X('B', 0, SPI_SS, 0) \
	X('B', 1, SPI_SCK, 0) \
	X('B', 2, SPI_MOSI, 0) \
	X('B', 3, SPI_MISO, 0) \
	X('E', 3, SERVO_CLK, 0) \
	X('E', 4, SERVO_CLK, 1) \
	X('E', 5, SERVO_CLK, 2) \
	X('B', 7, SERVO_CLK, 3) \
	X('E', 6, SERVO_RST, 0)

#endif
