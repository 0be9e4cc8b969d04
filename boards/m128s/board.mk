# OR-AVR-M128-S: ATmega128 at 7.3728 MHz.
BOARD_MCU := atmega128
BOARD_F_CPU := 7372800UL
# Drivers after introspection, in register order (SPEC section 1).
BOARD_DRIVERS := gpio spi adc servo
# Servo pulse hardware: CD4017 counters clocked by timer compare outputs.
BOARD_SERVO_HW := servo_4017
