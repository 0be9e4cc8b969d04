# ORFA firmware, simulator and tests.
#
#   make [BOARD=m32d|m128s] [MODE=gate|slave] [BAUD=115200|...|auto] [ADDR=0x10] [DRIVERS="..."]
#   make all-boards     every board and mode
#   make robot          the slave boards of the simulated test robot
#   make size           flash and static RAM of every build in build/
#   make flash          write the build's .hex with avrdude [PROGRAMMER=usbasp] [PORT=...]
#   make fuses          write the board's fuses (boards/<board>/board.mk) with avrdude
#   make map            host/orfa/maps/<board>.json from the C definitions
#   make sim            build/sim/orfa-sim
#   make unit           host-compiled unit tests of the parser and register logic
#   make fuzz-short     each libFuzzer harness a few seconds (about a minute in all)
#   make fuzz           the long run: 10^7 executions per harness (docs/fuzzing.md)
#   make test           install what is missing, build everything, run all tests
#   make bench          cycle-exact benchmark table
#   make doc-images     the pictures in docs/img/, made by the tests that draw them
#   make soak           the long differential soak (SOAK_REQUESTS, SOAK_SEED)
#   make demo           a simulated M32-D gateway to talk to
#   make demo-robot     the same with two slave boards on its I2C bus

BOARD ?= m32d
MODE ?= gate
# The line's rate after reset (docs/protocol.md; host/orfa/protocol.py's DEFAULT_BAUD).
DEFAULT_BAUD := 115200
BAUD ?= $(DEFAULT_BAUD)
ADDR ?= 0x10

BOARDS := m32d m128s
# The serial rates of docs/protocol.md ("The line"): a fixed-rate build takes
# any of BAUD_RATES; BAUD=auto detects AUTOBAUD_RATES (firmware/autobaud.c),
# all of them (230400 and 460800: UBRR 1 and 0 at 7.3728 MHz). host/orfa/protocol.py
# has both lists (tests/host/test_build.py keeps them equal to these).
AUTOBAUD_RATES := 2400 4800 9600 14400 19200 28800 38400 57600 76800 115200 230400 460800
BAUD_RATES := $(AUTOBAUD_RATES)
# 921600 (UBRR 0 with U2X) divides the crystal too, but a character lasts 80
# cycles there: measured in docs/protocol.md ("The line"), the firmware does
# not keep up.
ifeq ($(BAUD),921600)
$(error BAUD=921600 is refused: a character lasts 80 cycles there, about what the firmware's receive path takes per character (docs/protocol.md, "The line"); use 460800 or less)
endif
ifeq ($(filter $(BAUD),$(BAUD_RATES) auto),)
$(error BAUD=$(BAUD) is not a rate of the line: use one of $(BAUD_RATES), or auto)
endif
MODES := gate slave
# A slave has no serial port: BAUD is the gateway's, and a slave build is the
# same whatever it says (FW_BAUD below). Said once when
# given on make's own command line; a rate make refuses is refused here too.
ifeq ($(MODE)$(origin BAUD)$(MAKELEVEL),slavecommand line0)
$(info make: BAUD=$(BAUD) ignored: MODE=slave has no serial port (the gateway's BAUD sets the line's rate))
endif

ifeq ($(wildcard boards/$(BOARD)/board.mk),)
$(error BOARD=$(BOARD): no such board (boards/: $(notdir $(wildcard boards/*))))
endif
include boards/$(BOARD)/board.mk
include tools/board_facts.mk
# The MCU and the clock: board.h holds them (the simulator and the map read
# that header too, and the firmware has them as -mmcu and -DF_CPU).
BOARD_MCU := $(call board_mcu,$(BOARD))
BOARD_F_CPU := $(call board_f_cpu,$(BOARD))
ifeq ($(BOARD_MCU),)
$(error boards/$(BOARD)/board.h: no $(HASH)define BOARD_MCU_NAME "<mcu>")
endif
ifeq ($(BOARD_F_CPU),)
$(error boards/$(BOARD)/board.h: no $(HASH)define BOARD_CLOCK_HZ <hz>UL)
endif

# The slave's bus address, 8-bit form (docs/registers.md, "On a slave board"):
# the rule of firmware/i2c_addr.h (even, I2C_ADDR_MIN..I2C_ADDR_MAX: not one
# of the addresses I2C reserves), whose limits are read from there.
ifeq ($(MODE),slave)
ADDR_MIN := $(call c_define,firmware/i2c_addr.h,I2C_ADDR_MIN)
ADDR_MAX := $(call c_define,firmware/i2c_addr.h,I2C_ADDR_MAX)
ifeq ($(and $(ADDR_MIN),$(ADDR_MAX)),)
$(error firmware/i2c_addr.h: no $(HASH)define I2C_ADDR_MIN / I2C_ADDR_MAX)
endif
ADDR_NUM := $(shell v=$$(printf '%d' '$(ADDR)' 2>/dev/null) && echo $$v)
ifeq ($(strip $(ADDR)),)
ADDR_NUM :=
endif
ifeq ($(ADDR_NUM),)
$(error ADDR=$(ADDR) is not a number: give the 8-bit bus address, e.g. ADDR=0x10)
endif
ifneq ($(shell test $(ADDR_NUM) -ge 0 -a $(ADDR_NUM) -le 255 && echo ok),ok)
$(error ADDR=$(ADDR) is not an 8-bit bus address ($(ADDR_MIN)..$(ADDR_MAX), even))
endif
ifneq ($(shell expr $(ADDR_NUM) % 2),0)
$(error ADDR=$(ADDR) is odd: give the 8-bit form, whose bit 0 is the R/W bit (e.g. ADDR=0x10 for 7-bit 0x08))
endif
ifneq ($(shell test $(ADDR_NUM) -ge $$(printf %d $(ADDR_MIN)) -a \
	$(ADDR_NUM) -le $$(printf %d $(ADDR_MAX)) && echo ok),ok)
$(error ADDR=$(ADDR) is reserved by I2C: use $(ADDR_MIN)..$(ADDR_MAX))
endif
endif

# Drivers linked into the register table, in register order. Leave drivers out
# with DRIVERS="..." (introspection is always in: it owns registers 0x00-0x01).
DRIVERS ?= $(BOARD_DRIVERS)

# BUILD=dir puts one more build elsewhere (the test robot's slaves at their addresses).
# build/<board>-<mode>/ is the build of the variables given, whatever BAUD
# says (the project's contract: `make BOARD=m32d MODE=gate BAUD=auto` is
# build/m32d-gate/orfa.elf). The gateways at other rates that the tools run
# (`orfa --sim B --baud R`, `orfa flash --rate R`: orfa.locate.gateway_firmware)
# are made apart, in build/<board>-gate-<BAUD>/ (gate_build; make gate-rates).
BUILD ?= build/$(BOARD)-$(MODE)
gate_build = build/$(1)-gate-$(2)
# -fno-move-loop-invariants -mstrict-X: 130 bytes less on the M32-D gateway,
# no slower where it counts (make bench). -mcall-prologues: register saves
# through one shared routine, 250 bytes less; interrupt handlers keep their
# own, and the local latency is the same over the phases of the clock tick.
# -fno-tree-sink -fno-tree-copyrename: 50 bytes less, the latency the same.
FW_OPT ?= -Os -fno-move-loop-invariants -mstrict-X -mcall-prologues -fno-tree-sink -fno-tree-copyrename
CC := avr-gcc
OBJCOPY := avr-objcopy
AVR_SIZE := avr-size

# The rate compiled in: BAUD's for a gateway; a slave's is the default, whatever
# BAUD says (no serial port: its build is the same).
FW_BAUD := $(if $(filter gate,$(MODE)),$(BAUD),$(DEFAULT_BAUD))
FW_CFLAGS := -mmcu=$(BOARD_MCU) -DF_CPU=$(BOARD_F_CPU) \
	$(if $(filter auto,$(FW_BAUD)),'-DORFA_BAUD_RATES(X)=$(foreach r,$(AUTOBAUD_RATES),X($(r)))',-DORFA_BAUD=$(FW_BAUD)) \
	-DORFA_BAUD_TOP=$(if $(filter auto,$(FW_BAUD)),$(lastword $(AUTOBAUD_RATES)),$(FW_BAUD)) \
	-DORFA_ADDR=$(ADDR) -DORFA_MODE_$(MODE) \
	-std=gnu99 $(FW_OPT) $(FW_DEBUG) -flto -Wall -Wextra -Werror -ffunction-sections -fdata-sections \
	-fshort-enums -I. -Iboards/$(BOARD) \
	'-DORFA_DRIVER_LIST=$(foreach d,$(DRIVERS),X($(d)))'
# -mrelax: the linker turns calls and jumps within reach into rcall/rjmp
# (about 200 bytes less on the M32-D gateway).
FW_LDFLAGS := -mmcu=$(BOARD_MCU) $(FW_OPT) $(FW_DEBUG) -flto -mrelax -Wl,--gc-sections

# Each driver's hardware part, where it has one.
DRV_HW_spi := drivers/spi_hw.c
DRV_HW_adc := drivers/adc_hw.c
DRV_HW_motor := drivers/motor_hw.c
DRV_HW_servo := $(foreach f,$(BOARD_SERVO_HW),drivers/$(f).c)

FW_SRC := firmware/main.c firmware/regmap.c firmware/xact.c firmware/intro.c firmware/sys.c \
	firmware/mcu.c firmware/clock.c firmware/clock_now.c firmware/pins.c firmware/board_pins.c firmware/port_io_avr.c \
	$(foreach d,$(DRIVERS),drivers/drv_$(d).c $(DRV_HW_$(d)))
ifeq ($(MODE),gate)
FW_SRC += firmware/uart.c $(if $(filter auto,$(BAUD)),firmware/autobaud.c,firmware/uart_rate.c) \
	firmware/twi_master.c firmware/twi_rate.c \
	serialgate/sg_rx.c serialgate/sg_parse.c serialgate/sg_exec.c serialgate/sg_gate.c
else ifeq ($(MODE),slave)
FW_SRC += i2c_slave/slave_fsm.c i2c_slave/i2c_slave.c
else
$(error MODE=$(MODE): use MODE=gate (serial gateway) or MODE=slave (I2C slave at ADDR))
endif
FW_OBJ := $(patsubst %.c,$(BUILD)/%.o,$(FW_SRC))

.PHONY: map map-board print-baud-rates print-autobaud-rates print-gate-rates firmware flash fuses all-boards gate-rates robot size sim unit fuzz fuzz-short test bench profile soak demo demo-robot doc-images clean setup
.DEFAULT_GOAL := firmware

firmware: $(BUILD)/orfa.elf $(BUILD)/orfa.hex

$(BUILD)/%.o: %.c $(BUILD)/flags
	@mkdir -p $(dir $@)
	$(CC) $(FW_CFLAGS) -MMD -MP -c $< -o $@

# Rebuild when the configuration changes (DRIVERS, BAUD, ADDR).
$(BUILD)/flags: FORCE
	$(shell mkdir -p $(BUILD))$(file >$@.new,$(FW_CFLAGS) $(FW_LDFLAGS))@cmp -s $@.new $@ || mv $@.new $@

$(BUILD)/orfa.elf: $(FW_OBJ) $(BUILD)/flags
	$(CC) $(FW_LDFLAGS) $(FW_OBJ) -o $@

$(BUILD)/orfa.hex: $(BUILD)/orfa.elf
	$(OBJCOPY) -O ihex -R .eeprom $< $@

all-boards:
	@set -e; for b in $(BOARDS); do for m in $(MODES); do \
		$(MAKE) --no-print-directory BOARD=$$b MODE=$$m firmware; done; done

# Each board's gateway at the fast rates and with autobaud, for a simulated
# board at those rates (`orfa --sim B --baud R`, orfa.locate.gateway_firmware,
# which makes any other rate on demand) and the installed package:
# build/<board>-gate-<rate>/.
GATE_RATES := 230400 460800 auto
gate-rates:
	@set -e; for b in $(BOARDS); do for r in $(GATE_RATES); do \
		$(MAKE) --no-print-directory BOARD=$$b MODE=gate BAUD=$$r \
			BUILD=$(call gate_build,$$b,$$r) firmware; done; done

# The slave boards of the simulated test robot (tests/sim, tools/bench.py):
# BOARD:ADDR, each built into build/robot/<board>-<addr>/orfa.elf.
ROBOT_SLAVES := m128s:0x10 m32d:0x12 m128s:0x14 m32d:0x16 m128s:0x18 m32d:0x1A \
	m128s:0x1C m32d:0x1E

robot:
	@set -e; for s in $(ROBOT_SLAVES); do b=$${s%%:*}; a=$${s#*:}; \
		$(MAKE) --no-print-directory BOARD=$$b MODE=slave ADDR=$$a \
			BUILD=build/robot/$$b-$$a firmware; done

size:
	@tools/size.sh build

# The board map (tools/mapgen.c): registers, UIDs, pins, status and error
# codes as the firmware is built, for the host package, tests and docs.
MAP_OUT ?= host/orfa/maps
map:
	@set -e; for b in $(BOARDS); do \
		$(MAKE) --no-print-directory BOARD=$$b MODE=gate map-board; done

map-board: tools/mapgen.c boards/$(BOARD)/board.mk
	@mkdir -p build/map $(MAP_OUT)
	gcc -std=c99 -Wall -Wextra -Werror -I. -Iboards/$(BOARD) \
		'-DORFA_DRIVER_LIST=$(foreach d,$(BOARD_DRIVERS),X($(d)))' \
		'-DMAP_AVRDUDE_PART="$(BOARD_AVRDUDE_PART)"' '-DMAP_FUSES="$(BOARD_FUSES)"' \
		tools/mapgen.c -o build/map/mapgen-$(BOARD)
	build/map/mapgen-$(BOARD) > $(MAP_OUT)/$(BOARD).json.new
	@python3 -c 'import json,sys; json.load(open(sys.argv[1]))' $(MAP_OUT)/$(BOARD).json.new
	@mv $(MAP_OUT)/$(BOARD).json.new $(MAP_OUT)/$(BOARD).json

print-baud-rates:
	@echo $(BAUD_RATES)

print-autobaud-rates:
	@echo $(AUTOBAUD_RATES)

print-gate-rates:
	@echo $(GATE_RATES)

# --- flashing a real board (avrdude; docs/flashing.md) ----------------------
# The part and the fuses come from boards/$(BOARD)/board.mk. PROGRAMMER is
# passed to avrdude as it is (avrdude knows its programmers); no PORT, no -P.
# AVRDUDE_FLAGS: anything more for avrdude (-B 10 for a slow ISP clock, -v).
AVRDUDE ?= avrdude
PROGRAMMER ?= usbasp
PORT ?=
AVRDUDE_FLAGS ?=
AVRDUDE_CMD = $(AVRDUDE) -c $(PROGRAMMER) -p $(BOARD_AVRDUDE_PART) \
	$(if $(strip $(PORT)),-P $(strip $(PORT))) $(AVRDUDE_FLAGS)

AVRDUDE_CHECK = command -v $(firstword $(AVRDUDE)) >/dev/null || { echo \
	"make: $(firstword $(AVRDUDE)) not found: install avrdude (tools/setup.sh) or give AVRDUDE=/path/to/avrdude" >&2; \
	exit 127; }

# Built first with the same BAUD, ADDR, DRIVERS and BUILD as `make firmware`.
flash: $(BUILD)/orfa.hex
	@$(AVRDUDE_CHECK)
	$(strip $(AVRDUDE_CMD) -U flash:w:$<:i)

# name:0xVV in board.mk -> -U name:w:0xVV:m, in board.mk's order.
fuses:
	@$(AVRDUDE_CHECK)
	$(strip $(AVRDUDE_CMD) $(foreach f,$(BOARD_FUSES),-U $(subst :,:w:,$(f)):m))

# --- simulator (host C, Debian's libsimavr) --------------------------------
SIM_SRC := $(wildcard sim/*/*.c)
SIM_HDR := $(wildcard sim/*/*.h boards/*/board.h)
AVR_LIBC_INCLUDE ?= $(abspath $(dir $(shell avr-gcc -print-file-name=libc.a))../include)
SIM_CFLAGS := -std=gnu99 -O2 -g -Wall -Wextra -Werror -I. -Isim -I/usr/include/simavr -idirafter $(AVR_LIBC_INCLUDE)
SIM_LIBS := -lsimavr -lelf -lutil -lpthread -lm

sim: build/sim/orfa-sim build/sim-fw/twi_slave_echo.elf build/sim-fw/twi_slave_echo_m128.elf \
	build/sim-fw/twi_arb_master.elf build/sim-fw/irq_latency.elf build/sim-fw/autobaud_check.elf \
	build/sim-fw/profile_loop.elf build/sim-fw/profile_sleep.elf

# Test firmware for the simulator's bus tests (tests/sim/fw), not ORFA: the
# echo slave on an ATmega32 at 0x20 and on an ATmega128 at 0x22, a master
# that loses arbitration (ATmega32), a count of the instructions run after
# SEI and RETI before a pending interrupt (ATmega32), autobaud's pair
# analysis against its rule (the M32-D gateway's autobaud.c and rates), a
# loop of known instructions and a sleeping loop for the `profile` request
# (ATmega32).
# Each runs on a board's MCU at its clock (board.h).
SIM_FW_CFLAGS := -std=gnu99 -Os -Wall -Wextra -Werror
build/sim-fw/%_m128.elf: tests/sim/fw/%.c
	@mkdir -p $(dir $@)
	avr-gcc -mmcu=$(call board_mcu,m128s) -DF_CPU=$(call board_f_cpu,m128s) -DECHO_ADDR=0x22 \
		$(SIM_FW_CFLAGS) $< -o $@

build/sim-fw/autobaud_check.elf: firmware/autobaud.c firmware/uart_line.h boards/m32d/board.h
build/sim-fw/autobaud_check.elf: SIM_FW_CFLAGS += -I. -Iboards/m32d -fshort-enums \
	'-DORFA_BAUD_RATES(X)=$(foreach r,$(AUTOBAUD_RATES),X($(r)))'

build/sim-fw/%.elf: tests/sim/fw/%.c
	@mkdir -p $(dir $@)
	avr-gcc -mmcu=$(call board_mcu,m32d) -DF_CPU=$(call board_f_cpu,m32d) $(SIM_FW_CFLAGS) $< -o $@

build/sim/orfa-sim: $(SIM_SRC) $(SIM_HDR)
	@mkdir -p $(dir $@)
	gcc $(SIM_CFLAGS) $(SIM_SRC) -o $@ $(SIM_LIBS)

# --- tests, benchmark, demo ------------------------------------------------
unit:
	@$(MAKE) --no-print-directory -C tests/unit

# libFuzzer harnesses (clang; tests/fuzz, docs/fuzzing.md): from the corpus
# kept in tests/fuzz/corpus/, new inputs to a temporary copy.
FUZZ_SHORT_TIME ?= 8
FUZZ_RUNS ?= 10000000
fuzz-short:
	@$(MAKE) --no-print-directory -C tests/fuzz short SHORT_TIME=$(FUZZ_SHORT_TIME)

fuzz:
	@$(MAKE) --no-print-directory -C tests/fuzz long RUNS=$(FUZZ_RUNS)

setup:
	@tools/setup.sh

test: setup
	@$(MAKE) --no-print-directory all-boards robot sim
	@$(MAKE) --no-print-directory unit
	@$(MAKE) --no-print-directory fuzz-short
	python3 -m pytest -q tests

# The pictures in docs/img/: each test file here saves its images in
# $ORFA_SHOTS (default build/shots/); add a file to draw one more.
DOC_IMAGE_TESTS := tests/sim/test_dash.py tests/sim/test_plot.py tests/sim/test_capture_doc.py
doc-images:
	@$(MAKE) --no-print-directory all-boards robot sim
	ORFA_SHOTS=docs/img python3 -m pytest -q $(DOC_IMAGE_TESTS)

bench: setup
	@$(MAKE) --no-print-directory all-boards robot sim
	python3 tools/bench.py

# Where a gateway's cycles go in the robot control loop (tools/profile.py): a
# table by source file for each board at each rate above 115200.
profile: setup
	@$(MAKE) --no-print-directory sim
	@set -e; for b in $(BOARDS); do for r in $(filter-out auto,$(GATE_RATES)); do \
		python3 tools/profile.py --board $$b --baud $$r; echo; done; done

# Seeded random requests against a simulated robot, every reply compared with
# the reference model of the protocol (tests/sim/spec_model.py); docs/testing.md.
SOAK_REQUESTS ?= 100000
SOAK_SEED ?= 8
soak: setup
	@$(MAKE) --no-print-directory all-boards robot sim
	python3 tools/soak.py --requests $(SOAK_REQUESTS) --seed $(SOAK_SEED)

# The demos' console talks at the rate their gateway is built for (BAUD=460800;
# BAUD=auto: the autobaud build, found from the console's preamble): orfa sim
# runs the build for that rate (build/<board>-gate-<BAUD>/), and the default
# gateway stays the 115200 build.
DEMO_LINE = $(if $(filter auto,$(BAUD)),--autobaud,--baud $(BAUD))

demo: setup
	@$(MAKE) -s --no-print-directory BOARD=m32d MODE=gate BAUD=$(DEFAULT_BAUD) firmware sim
	@PYTHONPATH=host exec python3 -m orfa sim --board m32d --eeprom 0xA0 $(DEMO_LINE) --terminal

# A robot: the M32-D gateway, an M128-S slave at 0x10, an M32-D slave at 0x12,
# the EEPROM at A0 and the robot's sensors (an MPU-6050 IMU at D0, an
# HMC5883L compass at 3C, a LIS3MDL magnetometer at 38, a BMP280 barometer at
# EC, a 24LC32 EEPROM at A8), all on one simulated I2C bus.
demo-robot: setup
	@$(MAKE) --no-print-directory BOARD=m32d MODE=gate BAUD=$(DEFAULT_BAUD) firmware sim
	@$(MAKE) --no-print-directory BOARD=m128s MODE=slave ADDR=0x10 \
		BUILD=build/robot/m128s-0x10 firmware
	@$(MAKE) --no-print-directory BOARD=m32d MODE=slave ADDR=0x12 \
		BUILD=build/robot/m32d-0x12 firmware
	PYTHONPATH=host python3 -m orfa sim --board m32d --eeprom 0xA0 \
		--part mpu6050@0xD0 --part hmc5883l@0x3C --part lis3mdl@0x38 \
		--part bmp280@0xEC --part 24lc32@0xA8 \
		--slave m128s:0x10:build/robot/m128s-0x10/orfa.elf \
		--slave m32d:0x12:build/robot/m32d-0x12/orfa.elf $(DEMO_LINE) --terminal

clean:
	rm -rf build
	@$(MAKE) --no-print-directory -C examples clean

FORCE:

-include $(FW_OBJ:.o=.d)
