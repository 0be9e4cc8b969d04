/*
 * OR-AVR-M32-D: ATmega32 at 7.3728 MHz.
 *
 * Pin map (docs/boards.md, docs/board-m32d.md; reference wiring of the original board):
 *
 *   port  7     6     5     4     3     2     1     0
 *   A     S7    S6    S5    S4    S3    S2    S1    S0     servos 0-7 = ADC 7-0 = GPIO A
 *         AD7   AD6   AD5   AD4   AD3   AD2   AD1   AD0
 *   B     SCK   MISO  MOSI  SS    S12   S13   DIR2  DIR1   SPI, servos, motor direction
 *   C     S8    S9    S10   S11   -     -     SDA   SCL    servos, TWI (JTAG is switched off)
 *   D     -     -     PWM1  PWM2  -     -     TXD   RXD    motor PWM = servos 14/15, UART
 *                     S14   S15
 *
 * A pin belongs to one function at a time (firmware/pins.c); GPIO gets every
 * pin of its ports that no other function holds.
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
#define BOARD_NPORTS    4   /* A..D */

/* The gateway's serial port and the TWI pins. */
#define BOARD_UART      0
#define BOARD_TWI_PORT  'C'
#define BOARD_TWI_SCL   0
#define BOARD_TWI_SDA   1

/* The time base (firmware/clock.c): Timer2 at clk/8, whose overflows the
 * servo pulses (drivers/servo_pins.c) count on too; its compare unit is
 * theirs, and the clock's overflow turns it on again after a long wait
 * (clock_compare_from()). */
#define BOARD_CLOCK_TIMER 2
#define BOARD_CLOCK_COMPARE

/* GPIO driver (UID 0x0020): its ports, in register order. */
#define BOARD_GPIO_UID  0x0020
#define BOARD_GPIO_PORTS(X) X('A') X('B') X('C') X('D')

/* ADC: the port whose lines are ADC channels 0-7. */
#define BOARD_ADC_PORT  'A'

/* Servo driver (UID 0x0031): 16 channels, each on its own pin. */
#define BOARD_SERVO_UID 0x0031
#define BOARD_SERVO_CHANNELS 16
/* Received characters one receive interrupt hands on at most: its servo
 * interrupt waits for cycle-exact edges, and its wake-up's lead allows for
 * a receive interrupt of this many (drivers/servo_pins.c): as many as
 * reach the line in the 480 cycles the lead needs without one (the clock's
 * tick), at least one: 3 at 460800 baud, 2 at 230400, 1 at 115200 and
 * below, where the lead stays 480 (UART_CHAR_CYCLES, firmware/uart.h). */
#define BOARD_SERVO_LEAD_MIN 480
#define BOARD_RX_BURST ((BOARD_SERVO_LEAD_MIN + UART_CHAR_CYCLES - 1) / UART_CHAR_CYCLES)

/*
 * Fixed wiring: X(port, bit, function, index).
 *   UART_RX/UART_TX, TWI_SCL/TWI_SDA, SPI_SS/SPI_MOSI/SPI_MISO/SPI_SCK,
 *   MOTOR_PWM n (OC1A = motor 0, OC1B = motor 1), MOTOR_DIR n,
 *   SERVO n (channel n's output pin).
 */
#define BOARD_PINS(X) \
	X('D', 0, UART_RX, 0) \
	X('D', 1, UART_TX, 0) \
	X('C', 0, TWI_SCL, 0) \
	X('C', 1, TWI_SDA, 0) \
	X('B', 4, SPI_SS, 0) \
	X('B', 5, SPI_MOSI, 0) \
	X('B', 6, SPI_MISO, 0) \
	X('B', 7, SPI_SCK, 0) \
	X('D', 5, MOTOR_PWM, 0) \
	X('D', 4, MOTOR_PWM, 1) \
	X('B', 0, MOTOR_DIR, 0) \
	X('B', 1, MOTOR_DIR, 1) \
	X('A', 0, SERVO, 0) \
	X('A', 1, SERVO, 1) \
	X('A', 2, SERVO, 2) \
	X('A', 3, SERVO, 3) \
	X('A', 4, SERVO, 4) \
	X('A', 5, SERVO, 5) \
	X('A', 6, SERVO, 6) \
	X('A', 7, SERVO, 7) \
	X('C', 7, SERVO, 8) \
	X('C', 6, SERVO, 9) \
	X('C', 5, SERVO, 10) \
	X('C', 4, SERVO, 11) \
	X('B', 3, SERVO, 12) \
	X('B', 2, SERVO, 13) \
	X('D', 5, SERVO, 14) \
	X('D', 4, SERVO, 15)

#endif
