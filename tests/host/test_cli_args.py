"""The `orfa` command without a board: arguments, addresses, messages, the
scan grid, and the one-line errors for a missing or bad port."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from orfa import cli
from orfa.cli import bus
from orfa.cli.common import UsageError, address

HOST = str(Path(__file__).resolve().parents[2] / "host")


class Args:
    def __init__(self, seven_bit=False):
        self.seven_bit = seven_bit


def run(argv, capsys, env=None):
    """main(argv) in-process: (exit status, stdout, stderr)."""
    try:
        status = cli.main(argv)
    except SystemExit as exc:                  # argparse
        status = exc.code
    out, err = capsys.readouterr()
    return status, out, err


def orfa(*args, env=None):
    env = dict(os.environ if env is None else env, PYTHONPATH=HOST)
    return subprocess.run([sys.executable, "-m", "orfa"] + list(args), env=env,
                          capture_output=True, text=True, timeout=30)


def test_addresses_are_8_bit_unless_7_bit_is_asked():
    assert address(Args(), 0xA0) == 0xA0
    assert address(Args(seven_bit=True), 0x50) == 0xA0
    assert address(Args(seven_bit=True), 0x55) == 0xAA
    with pytest.raises(UsageError, match=r"0x21: an 8-bit address is even.*7-bit 0x21 is 0x42"):
        address(Args(), 0x21)
    with pytest.raises(UsageError, match="0x80: a 7-bit address is 0x00..0x7F"):
        address(Args(seven_bit=True), 0x80)
    with pytest.raises(UsageError, match="0x100"):
        address(Args(), 0x100)


def test_transfer_messages_as_i2ctransfer_takes_them():
    frames = bus.parse_messages(Args(), ["w3@0xA0", "0x10", "0x41", "66", "r2", "w0@0x10"])
    assert [(type(f).__name__, f.addr, getattr(f, "data", getattr(f, "count", None)))
            for f in frames] == [("Write", 0xA0, b"\x10\x41\x42"), ("Read", 0xA0, 2),
                                 ("Write", 0x10, b"")]
    (frame,) = bus.parse_messages(Args(seven_bit=True), ["r1@0x50"])
    assert frame.addr == 0xA0


@pytest.mark.parametrize("words, message", [
    (["r2"], "the first message needs @ADDR"),
    (["w2@0xA0", "0x10"], "2 data bytes must follow"),
    (["w2@0xA0", "0x10", "r1"], "2 data bytes must follow"),
    (["w1@0xA0", "0x100"], "data bytes are 0..0xFF"),
    (["r0@0xA0"], "a read reads 1 byte or more"),
    (["x1@0xA0"], "a message is {r|w}LENGTH"),
    (["w1@0xA1", "0"], "an 8-bit address is even"),
    (["w1@zz", "0"], "ADDR like 0xA0"),
])
def test_bad_transfer_messages(words, message):
    with pytest.raises(UsageError) as exc:
        bus.parse_messages(Args(), words)
    assert message in str(exc.value)


def test_scan_grid_is_i2cdetects():
    assert bus.scan_grid([0x08, 0x55, 0x77], 0x08, 0x77) == "\n".join([
        "     0  1  2  3  4  5  6  7  8  9  a  b  c  d  e  f",
        "00:                         08 -- -- -- -- -- -- --",
        "10: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "20: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "30: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "40: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "50: -- -- -- -- -- 55 -- -- -- -- -- -- -- -- -- --",
        "60: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "70: -- -- -- -- -- -- -- 77",
    ])
    assert bus.scan_grid([0x00], 0, 0x7F).splitlines()[1].startswith("00: 00 -- --")


def test_no_board_is_a_usage_error(capsys, monkeypatch):
    monkeypatch.delenv("ORFA_PORT", raising=False)
    assert run(["version"], capsys) == (
        2, "", "orfa: no board: give --port URL (or set ORFA_PORT) or --sim BOARD"
               " (m32d|m128s)\n")


def test_port_and_sim_exclude_each_other(capsys):
    status, out, err = run(["--port", "loop://", "--sim", "m32d", "version"], capsys)
    assert status == 2 and "not allowed with argument" in err


def test_sim_devices_need_sim(capsys):
    assert run(["--port", "loop://", "--eeprom", "0xA0", "scan"], capsys) == (
        2, "", "orfa: --eeprom describes a simulated board: give --sim BOARD too\n")


def test_a_bad_port_is_one_line_and_exit_2():
    result = orfa("--port", "/dev/ttyUSB9", "version")
    assert (result.returncode, result.stdout, result.stderr) == (
        2, "", "orfa: cannot open /dev/ttyUSB9: No such file or directory\n")


def test_the_port_comes_from_the_environment():
    result = orfa("scan", env=dict(os.environ, ORFA_PORT="/dev/ttyUSB9"))
    assert (result.returncode, result.stderr) == (
        2, "orfa: cannot open /dev/ttyUSB9: No such file or directory\n")


def test_a_bad_url_is_one_line():
    result = orfa("--port", "foo://x", "version")
    assert (result.returncode, result.stderr) == (
        2, "orfa: cannot open foo://x: invalid URL, protocol 'foo' not known\n")


@pytest.mark.parametrize("argv, message", [
    (["--port", "loop://", "read", "0xA1", "0"], "address 0xA1: an 8-bit address is even"),
    (["--port", "loop://", "read", "0xA0", "0", "61"], "COUNT is 1..60"),
    (["--port", "loop://", "read", "0xA0", "0", "0"], "COUNT is 1..60"),
    (["--port", "loop://", "write", "0xA0", "0"] + ["1"] * 62,
     "request of 130 characters, the limit is 128"),
    (["--port", "loop://", "transfer", "r63@0xA0"], "reply of 129 characters, the limit is 127"),
])
def test_bad_arguments_refused_before_sending(argv, message, capsys):
    status, out, err = run(argv, capsys)
    assert status == 2 and out == "" and message in err and err.count("\n") == 1


def test_a_request_over_the_limit_is_refused_on_the_host(capsys):
    status, out, err = run(["request", "--port", "loop://", "V" * 129], capsys)
    assert (status, out) == (1, "")
    assert err == "orfa: request of 129 characters, the limit is 128\n"


def test_every_command_has_help_with_an_example(capsys):
    parser = cli.build_parser()
    commands = parser._subparsers._group_actions[0].choices
    ours = {"version", "scan", "read", "write", "transfer", "request", "drivers", "servo",
            "motor", "adc", "gpio", "spi", "status", "console", "sim"}
    assert ours <= set(commands)
    for name in sorted(ours):
        sub = commands[name]
        assert "example" in (sub.epilog or ""), name
        status, out, err = run([name, "--help"], capsys)
        assert status == 0 and out.startswith("usage: orfa " + name), name


def test_flash_plugs_in_when_orfa_flash_is_there(monkeypatch, capsys):
    """orfa.flash (another module) registers `flash` with add_parser(subparsers)."""
    import importlib.machinery
    import types
    flash = types.ModuleType("orfa.flash")
    flash.__spec__ = importlib.machinery.ModuleSpec("orfa.flash", None)

    def add_parser(sub):
        cmd = sub.add_parser("flash", help="program a board", epilog="example: orfa flash")
        cmd.set_defaults(func=lambda args: print("flashing") or 0)
        return cmd
    flash.add_parser = add_parser
    monkeypatch.setitem(sys.modules, "orfa.flash", flash)
    assert run(["flash"], capsys) == (0, "flashing\n", "")


# --- issue 16: numbers that overflow, hang or mean nothing ----------------------

#: a simulator that cannot start: on a build that took the bad number, `sim`
#: ends there (never runs on, never waits on a line)
NO_FIRMWARE = ["--firmware", "/nonexistent/orfa.elf"]


def one_usage_error(status, out, err, option):
    """Exit 2, nothing on stdout, one line naming the option, no traceback."""
    assert status == 2 and out == "", err
    assert len(err.splitlines()) == 1 and "argument %s:" % option in err, err
    assert err.startswith("orfa") and "error:" in err, err


@pytest.mark.parametrize("argv, option", [
    (["--timeout", "inf", "version"], "--timeout"),
    (["--timeout", "1e20", "version"], "--timeout"),
    (["--timeout", "nan", "version"], "--timeout"),
    (["--timeout", "0", "version"], "--timeout"),
    (["--timeout", "-1", "version"], "--timeout"),
    (["version", "--timeout", "inf"], "--timeout"),
    (["--baud", "99999999999999999999", "version"], "--baud"),
    (["--baud", "0", "version"], "--baud"),
    (["scan", "--baud", "0"], "--baud"),
    (["adc", "--vref", "nan"], "--vref"),
    (["adc", "--vref", "-1"], "--vref"),
    (["adc", "--vref", "inf"], "--vref"),
    (["adc", "--vref", "0"], "--vref"),
    (["adc", "--watch", "inf"], "--watch"),
    (["adc", "--watch", "nan"], "--watch"),
    (["adc", "--watch", "-1"], "--watch"),
    (["sim", "--baud", "99999999999999999999", "--terminal"] + NO_FIRMWARE, "--baud"),
    (["sim", "--baud", "0", "--terminal"] + NO_FIRMWARE, "--baud"),
])
def test_numbers_that_overflow_or_mean_nothing_are_usage_errors(argv, option, capsys,
                                                                monkeypatch):
    monkeypatch.delenv("ORFA_PORT", raising=False)
    one_usage_error(*run(argv, capsys), option)


def test_sane_numbers_are_taken():
    args = cli.build_parser().parse_args(["--timeout", "0.25", "--baud", "9600", "adc",
                                          "--vref", "2.5", "--watch", "0"])
    assert (args.timeout, args.baud, args.vref, args.watch) == (0.25, 9600, 2.5, 0.0)


@pytest.mark.parametrize("argv, option", [
    (["--sim", "m32d", "--eeprom", "0xA1", "version"], "--eeprom"),
    (["--sim", "m32d", "--eeprom", "0xAA", "version"], "--eeprom"),
    (["--sim", "m32d", "--slave", "m128s:0xAA", "version"], "--slave"),
    (["sim", "--eeprom", "0xA1"] + NO_FIRMWARE, "--eeprom"),
    (["sim", "--eeprom", "0xAA"] + NO_FIRMWARE, "--eeprom"),
    (["sim", "--eeprom", "0x02"] + NO_FIRMWARE, "--eeprom"),
])
def test_eeprom_addresses_are_checked_as_slave_addresses_are(argv, option, capsys):
    """An odd address, a reserved one, or the gateway's own 0xAA: one line
    from the command line, not the simulator's three (its command line)."""
    status, out, err = run(argv, capsys)
    one_usage_error(status, out, err, option)
    assert "command:" not in err
    if "0xAA" in argv[-1] or "0xAA" in " ".join(argv):
        assert "the gateway's own address" in err


@pytest.mark.parametrize("argv", [
    ["--sim", "m32d", "--part", "bmp280@0xED", "version"],
    ["--sim", "m32d", "--part", "24lc32@0xAA", "version"],
    ["--sim", "m32d", "--part", "bmp280@0x02", "version"],
    ["--sim", "m32d", "--part", "bmp280@EC", "version"],
    ["--sim", "m32d", "--part", "bmp280", "version"],
    ["--sim", "m32d", "--part", "@0xEC", "version"],
    ["sim", "--part", "bmp280@0xEF"] + NO_FIRMWARE,
    ["sim", "--part", "24lc32@0xF0:wp"] + NO_FIRMWARE,
])
def test_part_addresses_are_checked_as_eeprom_addresses_are(argv, capsys):
    status, out, err = run(argv, capsys)
    one_usage_error(status, out, err, "--part")
    assert "command:" not in err
    if "0xAA" in " ".join(argv):
        assert "the gateway's own address" in err


def test_a_part_describes_a_simulated_board(capsys, monkeypatch):
    monkeypatch.delenv("ORFA_PORT", raising=False)
    assert run(["--port", "loop://", "--part", "bmp280@0xEC", "scan"], capsys) == (
        2, "", "orfa: --part describes a simulated board: give --sim BOARD too\n")


def test_a_part_where_another_device_is_is_one_line(capsys):
    assert run(["--sim", "m32d", "--eeprom", "0xA8", "--part", "24lc32@0xA8", "version"],
               capsys) == (2, "", "orfa: --part 0xA8: --eeprom put a device there already\n")


def test_two_devices_at_one_address_is_one_line(capsys):
    assert run(["--sim", "m32d", "--eeprom", "0xA0", "--slave", "m128s:0xA0", "version"],
               capsys) == (2, "", "orfa: --slave 0xA0: --eeprom put a device there already\n")


def test_an_address_out_of_range_says_so(capsys):
    """`orfa read 0x100 0` is not about evenness: 0x100 is no 8-bit address."""
    status, out, err = run(["--port", "loop://", "read", "0x100", "0"], capsys)
    assert (status, out, err) == (
        2, "", "orfa: address 0x100: out of range: an 8-bit address is 0x00..0xFE\n")
    with pytest.raises(UsageError, match="-2: out of range"):
        address(Args(), -2)


def test_an_explicit_sim_wins_over_the_environments_port(monkeypatch):
    """ORFA_PORT is a default: `orfa --sim m32d ...` does not clash with it
    (the board --sim starts is the one used), while an explicit --port does."""
    from orfa.cli import common
    used = []

    class FakeSim:
        def start(self):
            return self

        def gateway(self, *a, **kw):
            used.append("sim")
            return contextlib_nullcontext("sim gateway")

        def stop(self):
            pass

    monkeypatch.setattr(common, "sim_board", lambda *a, **kw: FakeSim())
    monkeypatch.setenv("ORFA_PORT", "/dev/ttyUSB9")
    args = cli.build_parser().parse_args(["--sim", "m32d", "version"])
    with common.connect(args) as gw:
        assert gw == "sim gateway"
    args = cli.build_parser().parse_args(["version", "--sim", "m32d"])
    with common.connect(args) as gw:
        assert gw == "sim gateway"
    args = cli.build_parser().parse_args(["--port", "loop://", "version", "--sim", "m32d"])
    with pytest.raises(UsageError, match="give --port or --sim, not both"):
        with common.connect(args):
            pass


def contextlib_nullcontext(value):
    import contextlib
    return contextlib.nullcontext(value)


def test_help_says_which_rates_the_gateway_runs(capsys, monkeypatch):
    """`orfa --help` under --baud: the gateway's builds' rates (to 460800)
    and that --sim runs the build for the rate (it said only the default)."""
    monkeypatch.setenv("COLUMNS", "200")
    status, out, _ = run(["--help"], capsys)
    assert status == 0
    baud = [line for line in out.splitlines() if line.lstrip().startswith("--baud BAUD")]
    assert baud == ["  --baud BAUD           serial rate, the gateway's BAUD (default 115200; its"
                    " builds run 2400..460800); --sim runs the gateway built for it"]
