"""Each fact in one place, the rest read from it: the boards' clock (board.h),
the bus address rule (firmware/i2c_addr.h). These tests fail when a copy
appears again or when a reader of the fact stops agreeing with it."""

import argparse
import subprocess
import sys
from pathlib import Path

import pytest

from orfa import boardmap, flash, sim
from orfa.cli import common

ROOT = Path(__file__).resolve().parents[2]

#: Where the clock's number may stand: its one place, the maps generated
#: from it, and prose.
CLOCK_PLACES = ("boards/*/board.h", "host/orfa/maps/*.json", "docs/*.md", "README.md")


def tracked_files():
    r = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip("not a git work tree: %s" % r.stderr.strip())
    return [Path(name) for name in r.stdout.splitlines()]


def test_the_clock_is_written_once():
    clock = str(boardmap.F_CPU)
    strays = []
    for path in tracked_files():
        if any(path.match(pattern) for pattern in CLOCK_PLACES):
            continue
        try:
            text = (ROOT / path).read_text()
        except (UnicodeDecodeError, FileNotFoundError):
            continue
        strays += ["%s:%d" % (path, n) for n, line in enumerate(text.splitlines(), 1)
                   if clock in line]
    assert strays == [], "the clock stands again outside board.h: %s" % ", ".join(strays)


def test_every_board_has_the_one_clock():
    assert {boardmap.load(b).f_cpu for b in boardmap.BOARDS} == {boardmap.F_CPU}


def test_maps_that_differ_in_a_shared_fact_are_an_error(monkeypatch):
    maps = {"m32d": {"f_cpu": 8000000}, "m128s": {"f_cpu": 16000000}}
    monkeypatch.setattr(boardmap, "_read", maps.__getitem__)
    with pytest.raises(ValueError, match="the board maps differ in 'f_cpu'"):
        boardmap._shared("f_cpu")


@pytest.fixture(scope="module")
def c_rule(tmp_path_factory):
    """The 8-bit addresses firmware/i2c_addr.h's I2C_ADDR_OK accepts."""
    out = tmp_path_factory.mktemp("addr")
    src = out / "rule.c"
    src.write_text('#include <stdio.h>\n#include "firmware/i2c_addr.h"\n'
                   'int main(void) { for (int a = 0; a < 256; a++) if (I2C_ADDR_OK(a))'
                   ' printf("%d\\n", a); return 0; }\n')
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Werror", "-I", str(ROOT), str(src),
                    "-o", str(out / "rule")], check=True, timeout=60)
    r = subprocess.run([str(out / "rule")], capture_output=True, text=True, check=True)
    return {int(line) for line in r.stdout.split()}


def test_the_host_has_the_address_rule_of_the_c(c_rule):
    assert {a for a in range(256) if boardmap.address_ok(a)} == c_rule
    assert (boardmap.ADDRESS_MIN, boardmap.ADDRESS_MAX) == (min(c_rule), max(c_rule))
    assert boardmap.ADDRESS_TEXT == "even, 0x%02X..0x%02X" % (min(c_rule), max(c_rule))


def refused(check, addr):
    try:
        check(addr)
    except (ValueError, argparse.ArgumentTypeError, flash.FlashError) as exc:
        return boardmap.ADDRESS_TEXT in str(exc)
    return False


@pytest.mark.parametrize("name, check", [
    ("SimRobot slave", lambda a: sim.slave_spec(("m128s", a))),
    ("orfa sim --slave", lambda a: common.slave_spec("m128s:%d" % a)),
    ("orfa sim --eeprom", lambda a: common.eeprom_spec("%d" % a)),
    ("orfa sim --part", lambda a: common.part_spec("eeprom24@%d" % a)),
    ("orfa flash --addr", lambda a: flash.slave_elf("m128s", a)),
])
def test_every_host_check_is_the_rule(name, check, c_rule):
    wrong = [a for a in range(-2, 258) if refused(check, a) == (a in c_rule)]
    assert wrong == [], "%s disagrees with firmware/i2c_addr.h on %s" % (name, wrong)


@pytest.mark.parametrize("offset", [-2, -1, 0, 1])
@pytest.mark.parametrize("end", ["min", "max"])
def test_the_build_checks_the_rule(end, offset, c_rule):
    addr = (min(c_rule) if end == "min" else max(c_rule) + 1) + offset
    r = subprocess.run(["make", "--no-print-directory", "-s", "MODE=slave",
                        "ADDR=0x%02X" % addr, "print-baud-rates"],
                       cwd=ROOT, capture_output=True, text=True, timeout=60)
    assert (r.returncode == 0) == (addr in c_rule), r.stderr


def test_pins_have_the_functions_of_the_one_list():
    """firmware/board_fn.h's list, through the map (test_boardmap.py keeps
    the map what tools/mapgen.c writes): every board's pins use it, and the
    generated pages have a text for each of its names."""
    assert boardmap.PIN_FUNCTIONS[:2] == ("UART_RX", "UART_TX")
    for board in boardmap.BOARDS:
        assert {p.function for p in boardmap.load(board).pins} <= set(boardmap.PIN_FUNCTIONS)
    sys.path.insert(0, str(ROOT / "tools"))
    try:
        import docgen_en
        import docgen_ru
    finally:
        sys.path.remove(str(ROOT / "tools"))
    assert set(docgen_en.PIN_FUNCTIONS) == set(docgen_ru.PIN_FUNCTIONS) == \
        set(boardmap.PIN_FUNCTIONS)
