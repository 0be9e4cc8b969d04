# What make needs of a board, read from the file that holds it, so each fact
# is written once: boards/<board>/board.h holds the MCU and the clock (the
# firmware, the simulator and tools/mapgen.c read that header too), board.mk
# the driver list. Included by the Makefile, tests/unit and tests/fuzz.
#
#   $(call c_define,FILE,NAME)   VALUE of `#define NAME VALUE` in FILE, quotes off
#   $(call board_mcu,BOARD)      BOARD_MCU_NAME: atmega32
#   $(call board_f_cpu,BOARD)    BOARD_CLOCK_HZ, for -DF_CPU=
#   $(call board_drivers,BOARD)  board.mk's BOARD_DRIVERS as X(gpio) X(spi) ...
BOARD_FACTS_ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST)))..)
HASH := \#

# Make's own functions, no shell: `make fuses` and the error messages work
# with nothing but make on the PATH.
c_define = $(patsubst "%",%,$(patsubst C_DEFINE=%,%,$(filter C_DEFINE=%, \
	$(subst $(HASH)define $(2) ,C_DEFINE=,$(strip $(file <$(1)))))))
board_mcu = $(call c_define,$(BOARD_FACTS_ROOT)/boards/$(1)/board.h,BOARD_MCU_NAME)
board_f_cpu = $(call c_define,$(BOARD_FACTS_ROOT)/boards/$(1)/board.h,BOARD_CLOCK_HZ)
board_drivers = $(foreach d,$(shell sed -n 's/^BOARD_DRIVERS *:= *//p' \
	$(BOARD_FACTS_ROOT)/boards/$(1)/board.mk),X($(d)))
