#!/bin/sh
# Install what building and testing ORFA needs on a fresh Debian machine.
# Idempotent and quiet when everything is there already.
set -eu

# make and gcc build the simulator, the unit tests and the board maps.
# clang and its runtime (-fsanitize=fuzzer) for tests/fuzz: Debian's clang
# is 14 on bookworm, whose libFuzzer comes in libclang-rt-14-dev; the
# libclang-rt-dev package follows the default clang of each release. avrdude for
# `make flash`, `make fuses` and `orfa flash` (the tests use a stand-in).
# chromium and chromium-driver: the dashboard's test drives a real headless
# browser (Debian's; a browser that a PyPI package downloads cannot be fetched
# on a closed network). sigrok-cli (with its protocol decoders): the tests
# decode the simulator's VCD with sigrok's own uart decoder.
APT_PACKAGES="make gcc gcc-avr avr-libc binutils-avr simavr libsimavr-dev libelf-dev clang libclang-rt-dev avrdude chromium chromium-driver sigrok-cli"
# python module:pip package. matplotlib draws `orfa plot`, flask serves
# `orfa dash` (the extras orfa[plot] and orfa[dash]), selenium drives the
# browser in the dashboard's test.
# smbus2 and Pimoroni's bmp280 driver (which takes an SMBus as i2c_dev=), for
# the tests of orfa.smbus.
PY_PACKAGES="serial:pyserial pytest:pytest matplotlib:matplotlib flask:flask selenium:selenium smbus2:smbus2 bmp280:bmp280 typing_extensions:typing_extensions"
# Adafruit's CircuitPython drivers, for the tests of orfa.busio. Their
# metadata asks for Adafruit-Blinka, whose own dependencies a PC without a
# USB bridge does not need (sysv_ipc, a C extension for the Raspberry Pi;
# pyftdi and binho for the FT232H and Binho bridges): so each goes in
# without dependencies, and with it the part of Blinka that the drivers import
# (busio, digitalio: the names of their type annotations; micropython.const),
# its platform detection and PureIO. orfa.busio itself needs none of them.
PY_NODEPS_PACKAGES="busio:adafruit-blinka adafruit_platformdetect:adafruit-platformdetect Adafruit_PureIO:adafruit-pureio circuitpython_typing:adafruit-circuitpython-typing adafruit_bus_device:adafruit-circuitpython-busdevice adafruit_register:adafruit-circuitpython-register adafruit_mpu6050:adafruit-circuitpython-mpu6050 adafruit_lis3mdl:adafruit-circuitpython-lis3mdl adafruit_bmp280:adafruit-circuitpython-bmp280 adafruit_24lc32:adafruit-circuitpython-24lc32"

if [ "$(id -u)" -eq 0 ]; then
	SUDO=""
elif command -v sudo >/dev/null 2>&1; then
	SUDO="sudo"
else
	SUDO=""
fi

updated=""
apt_install() {
	if [ -z "$updated" ]; then
		$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
		updated=yes
	fi
	$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$@" >/dev/null
}

missing=""
for pkg in $APT_PACKAGES; do
	if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
		missing="$missing $pkg"
	fi
done
if [ -n "$missing" ]; then
	echo "setup: installing$missing"
	apt_install $missing
fi

PYTHON=${PYTHON:-python3}
if ! command -v "$PYTHON" >/dev/null 2>&1; then
	echo "setup: installing python3"
	apt_install python3 python3-pip
fi

# tests/host/test_install.py makes a venv with pip: Debian's python3 needs
# python3-venv for that (ensurepip).
if ! "$PYTHON" -c "import ensurepip" >/dev/null 2>&1; then
	echo "setup: installing python3-venv"
	apt_install python3-venv
fi

# The packages of a list ("module:package ...") whose module does not import.
pip_missing_of() {
	out=""
	for entry in $1; do
		module=${entry%%:*}
		package=${entry#*:}
		if ! "$PYTHON" -c "import $module" >/dev/null 2>&1; then
			out="$out $package"
		fi
	done
	echo "$out"
}
pip_missing=$(pip_missing_of "$PY_PACKAGES")
# pip itself: the install test fetches its wheels with it, even where
# pyserial and pytest came from Debian's packages.
if ! "$PYTHON" -m pip --version >/dev/null 2>&1; then
	echo "setup: installing python3-pip"
	apt_install python3-pip
fi
pip_install() {
	# Debian's python marks itself externally managed (PEP 668).
	"$PYTHON" -m pip install -q "$@" 2>/dev/null ||
		"$PYTHON" -m pip install -q --break-system-packages "$@"
}
if [ -n "$pip_missing" ]; then
	echo "setup: pip installing$pip_missing"
	pip_install $pip_missing
fi
# the drivers last, without their dependencies: what they import came above
pip_missing=$(pip_missing_of "$PY_NODEPS_PACKAGES")
if [ -n "$pip_missing" ]; then
	echo "setup: pip installing without dependencies$pip_missing"
	pip_install --no-deps $pip_missing
fi
