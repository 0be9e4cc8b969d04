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
# on a closed network).
APT_PACKAGES="make gcc gcc-avr avr-libc binutils-avr simavr libsimavr-dev libelf-dev clang libclang-rt-dev avrdude chromium chromium-driver"
# python module:pip package. matplotlib draws `orfa plot`, flask serves
# `orfa dash` (the extras orfa[plot] and orfa[dash]), selenium drives the
# browser in the dashboard's test.
PY_PACKAGES="serial:pyserial pytest:pytest matplotlib:matplotlib flask:flask selenium:selenium"

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

pip_missing=""
for entry in $PY_PACKAGES; do
	module=${entry%%:*}
	package=${entry#*:}
	if ! "$PYTHON" -c "import $module" >/dev/null 2>&1; then
		pip_missing="$pip_missing $package"
	fi
done
# pip itself: the install test fetches its wheels with it, even where
# pyserial and pytest came from Debian's packages.
if ! "$PYTHON" -m pip --version >/dev/null 2>&1; then
	echo "setup: installing python3-pip"
	apt_install python3-pip
fi
if [ -n "$pip_missing" ]; then
	echo "setup: pip installing$pip_missing"
	# Debian's python marks itself externally managed (PEP 668).
	"$PYTHON" -m pip install -q $pip_missing 2>/dev/null ||
		"$PYTHON" -m pip install -q --break-system-packages $pip_missing
fi
