"""The build's own checks: a slave's bus address (docs/registers.md, "On a
slave board"), the mode."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


#: make as a person's shell runs it, not as a sub-make of `make test`
#: (MAKELEVEL 1 there: make says some things only to a person's command line).
TOP_ENV = {k: v for k, v in os.environ.items() if k not in ("MAKELEVEL", "MAKEFLAGS", "MFLAGS")}


def make(*args, tmp_path):
    return subprocess.run(["make", "--no-print-directory", "-n", "BUILD=%s" % tmp_path] + list(args),
                          cwd=ROOT, capture_output=True, text=True, timeout=60, env=TOP_ENV)


@pytest.mark.parametrize("addr,why", [
    ("0x11", "is odd"), ("0xFF", "is odd"), ("0x00", "reserved"), ("0x0E", "reserved"),
    ("0xF0", "reserved"), ("0xFE", "reserved"), ("0x100", "not an 8-bit"),
    ("foo", "not a number"), ("", "not a number"),
])
@pytest.mark.parametrize("board", ["m32d", "m128s"])
def test_bad_slave_address_stops_the_build(board, addr, why, tmp_path):
    r = make("BOARD=" + board, "MODE=slave", "ADDR=" + addr, tmp_path=tmp_path)
    assert r.returncode != 0
    assert why in r.stderr and "ADDR=" + addr in r.stderr, r.stderr
    assert "avr-gcc" not in r.stdout        # stopped before compiling anything


@pytest.mark.parametrize("addr", ["0x10", "0x12", "0xEE", "16"])
def test_good_slave_address_builds(addr, tmp_path):
    r = make("BOARD=m32d", "MODE=slave", "ADDR=" + addr, tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "i2c_slave/i2c_slave.c" in r.stdout and "serialgate" not in r.stdout
    assert "firmware/uart.c" not in r.stdout   # the slave has no serial port


def test_unknown_mode_and_board(tmp_path):
    r = make("MODE=master", tmp_path=tmp_path)
    assert r.returncode != 0 and "MODE=master" in r.stderr
    r = make("BOARD=m64", tmp_path=tmp_path)
    assert r.returncode != 0 and "BOARD=m64" in r.stderr


@pytest.mark.parametrize("baud", ["1200", "115201", "9600x", "AUTO", "", "230401", "250000"])
def test_baud_that_is_not_a_line_rate_stops_the_build(baud, tmp_path):
    r = make("BOARD=m32d", "MODE=gate", "BAUD=" + baud, tmp_path=tmp_path)
    assert r.returncode != 0
    assert "BAUD=%s is not a rate of the line" % baud in r.stderr, r.stderr
    assert "avr-gcc" not in r.stdout


@pytest.mark.parametrize("board", ["m32d", "m128s"])
def test_921600_is_refused_with_its_reason(board, tmp_path):
    """docs/protocol.md, "The line": 921600 divides the crystal but the
    firmware does not keep up; make says so in one line and builds nothing."""
    r = make("BOARD=" + board, "MODE=gate", "BAUD=921600", tmp_path=tmp_path)
    assert r.returncode != 0
    refusal = [l for l in r.stderr.splitlines() if "BAUD=921600" in l]
    assert len(refusal) == 1 and "refused" in refusal[0] and "80 cycles" in refusal[0] \
        and "460800" in refusal[0], r.stderr
    assert "avr-gcc" not in r.stdout


@pytest.mark.parametrize("board", ["m32d", "m128s"])
def test_auto_baud_links_the_autobaud_module_only(board, tmp_path):
    r = make("BOARD=" + board, "MODE=gate", "BAUD=auto", tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "firmware/autobaud.c" in r.stdout and "firmware/uart_rate.c" not in r.stdout
    assert "-DORFA_BAUD_RATES" in r.stdout
    r = make("BOARD=" + board, "MODE=gate", "BAUD=9600", tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "firmware/uart_rate.c" in r.stdout and "firmware/autobaud.c" not in r.stdout
    assert "-DORFA_BAUD=9600" in r.stdout


def build_dir(*args):
    """The BUILD make's own default gives for these variables (nothing built)."""
    r = subprocess.run(["make", "-s", "--no-print-directory", "--eval",
                        "orfa-build-dir: ; @echo $(BUILD)"] + list(args) + ["orfa-build-dir"],
                       cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return r.stdout.splitlines()[-1]


@pytest.mark.parametrize("board", ["m32d", "m128s"])
@pytest.mark.parametrize("baud", ["230400", "460800", "auto", "9600", "115200"])
def test_a_gateway_build_is_in_its_board_and_modes_directory_at_every_rate(board, baud):
    """The project's contract: `make BOARD=<b> MODE=gate BAUD=auto` is
    build/<b>-gate/orfa.elf, as every rate's (make flash takes the .hex
    from there); gate-rates, which `orfa --sim B --baud R` and `orfa flash
    --rate R` use, puts each rate apart with BUILD, in build/<b>-gate-<R>/."""
    assert build_dir("BOARD=" + board, "MODE=gate", "BAUD=" + baud) == "build/%s-gate" % board
    assert build_dir("BOARD=" + board, "MODE=gate") == "build/%s-gate" % board
    assert build_dir("BOARD=" + board, "MODE=gate", "BAUD=" + baud, "BUILD=build/x") == "build/x"


@pytest.mark.parametrize("board", ["m32d", "m128s"])
def test_a_slave_ignores_baud_and_says_so(board, tmp_path):
    """A slave has no serial port: BAUD changes nothing in its build (its
    flags are the default rate's, so nothing is rebuilt either), and make
    says it once."""
    assert build_dir("BOARD=" + board, "MODE=slave", "BAUD=460800") == "build/%s-slave" % board
    r = make("-B", "BOARD=" + board, "MODE=slave", "BAUD=460800", tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    said = [l for l in r.stdout.splitlines() if "BAUD=460800" in l]
    assert said == ["make: BAUD=460800 ignored: MODE=slave has no serial port"
                    " (the gateway's BAUD sets the line's rate)"]
    plain = make("-B", "BOARD=" + board, "MODE=slave", tmp_path=tmp_path)
    assert r.stdout.replace(said[0] + "\n", "") == plain.stdout
    assert "BAUD" not in plain.stdout.replace("-DORFA_BAUD=115200", "") \
        .replace("-DORFA_BAUD_TOP=115200", "")


@pytest.mark.parametrize("target, name", [("print-baud-rates", "BAUD_RATES"),
                                          ("print-autobaud-rates", "AUTOBAUD_RATES")])
def test_host_knows_the_rates_the_build_knows(target, name):
    from orfa import protocol
    r = subprocess.run(["make", "--no-print-directory", "-s", target],
                       cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert tuple(int(x) for x in r.stdout.split()) == getattr(protocol, name)
    assert protocol.DEFAULT_BAUD in protocol.AUTOBAUD_RATES
    assert set(protocol.AUTOBAUD_RATES) <= set(protocol.BAUD_RATES)


@pytest.mark.parametrize("board", ["m32d", "m128s"])
def test_auto_baud_detects_only_the_autobaud_rates(board, tmp_path):
    """BAUD=auto gets AUTOBAUD_RATES, 2400..460800 (the Makefile's list)."""
    from orfa.protocol import AUTOBAUD_RATES
    r = make("BOARD=" + board, "MODE=gate", "BAUD=auto", tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "'-DORFA_BAUD_RATES(X)=%s'" % " ".join("X(%d)" % b for b in AUTOBAUD_RATES) \
        in r.stdout


@pytest.mark.parametrize("board", ["m32d", "m128s"])
def test_mcu_and_clock_come_from_board_h(board, tmp_path):
    """board.h holds the MCU and the clock (the simulator and tools/mapgen.c
    read it too); the build compiles with what the map says, and board.mk
    does not say them again (its value would be overridden unseen)."""
    from orfa import boardmap
    m = boardmap.load(board)
    r = make("BOARD=" + board, "MODE=gate", tmp_path=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "-mmcu=%s -DF_CPU=%dUL " % (m.mcu, m.f_cpu) in r.stdout
    board_mk = (ROOT / "boards" / board / "board.mk").read_text()
    assert "BOARD_MCU" not in board_mk and "F_CPU" not in board_mk


def copy_build_files(tmp_path):
    """What make reads before it compiles, into tmp_path, for a header to break."""
    for name in ("Makefile", "tools/board_facts.mk", "boards/m32d/board.mk",
                 "boards/m32d/board.h", "firmware/i2c_addr.h"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(ROOT / name, tmp_path / name)


@pytest.mark.parametrize("name, file", [
    ("BOARD_MCU_NAME", "boards/m32d/board.h"), ("BOARD_CLOCK_HZ", "boards/m32d/board.h"),
    ("I2C_ADDR_MIN", "firmware/i2c_addr.h"),
])
def test_a_header_without_its_fact_stops_the_build(name, file, tmp_path):
    copy_build_files(tmp_path)
    header = tmp_path / file
    text = header.read_text()
    assert "#define " + name in text
    header.write_text(text.replace("#define " + name, "#define NOT_" + name))
    r = subprocess.run(["make", "--no-print-directory", "-n", "MODE=slave", "ADDR=0x10"],
                       cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert r.returncode != 0
    assert "%s: no #define %s" % (file, name) in r.stderr, r.stderr
    assert r.stderr.count("\n") == 1 and "avr-gcc" not in r.stdout


def test_the_slave_address_rule_is_i2c_addr_h_s(tmp_path):
    """make takes its limits from firmware/i2c_addr.h: moved there, they
    move the build's check (and its message) too."""
    copy_build_files(tmp_path)
    header = tmp_path / "firmware" / "i2c_addr.h"
    header.write_text(header.read_text().replace("I2C_ADDR_MIN 0x10", "I2C_ADDR_MIN 0x20"))

    def run(addr):      # a target that needs no sources: the check is all
        return subprocess.run(["make", "--no-print-directory", "-s", "MODE=slave",
                               "ADDR=" + addr, "print-baud-rates"],
                              cwd=tmp_path, capture_output=True, text=True, timeout=60)
    r = run("0x1E")
    assert r.returncode != 0 and "ADDR=0x1E is reserved by I2C: use 0x20..0xEE" in r.stderr
    r = run("0x20")
    assert r.returncode == 0 and r.stderr == "", r.stderr
