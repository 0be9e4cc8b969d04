# OR-AVR-M32-D (its MCU and clock: board.h, read by the Makefile).
# Drivers after introspection, in register order (docs/board-m32d.md).
BOARD_DRIVERS := gpio spi adc motor servo
# Servo pulse hardware: one MCU pin per channel, edges as planned.
BOARD_SERVO_HW := servo_pins servo_plan
# avrdude's name of the MCU, and the fuses `make fuses` writes: external
# crystal, JTAG off, SPI programming kept on.
BOARD_AVRDUDE_PART := m32
BOARD_FUSES := lfuse:0xff hfuse:0xd9
