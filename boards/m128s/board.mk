# OR-AVR-M128-S: ATmega128 at 7.3728 MHz.
BOARD_MCU := atmega128
BOARD_F_CPU := 7372800UL
# Drivers after introspection, in register order (SPEC section 1).
BOARD_DRIVERS :=
