# OR-AVR-M128-S (its MCU and clock: board.h, read by the Makefile).
# Drivers after introspection, in register order (docs/board-m128s.md).
BOARD_DRIVERS := gpio spi adc servo
# Servo pulse hardware: CD4017 counters clocked by timer compare outputs.
BOARD_SERVO_HW := servo_4017
# avrdude's name of the MCU, and the fuses `make fuses` writes: external
# crystal, JTAG off, SPI programming kept on, ATmega103 mode off.
BOARD_AVRDUDE_PART := m128
BOARD_FUSES := lfuse:0xff hfuse:0xd9 efuse:0xff
