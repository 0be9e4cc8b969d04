"""`orfa` version, drivers, scan, read, write, transfer, request and console
against one simulated robot (M32-D gateway, EEPROM 0xA0, an M128-S slave at
0x10 and an M32-D slave at 0x12), run in-process through main(argv)."""

import pytest

from conftest import cli_runner, require_builds
from orfa.sim import SimRobot

EEPROM = 0xA0
NACK = ("ERROR 06: no ACK for an address byte (no device, bus not to be had,"
        " register not readable)")


@pytest.fixture(scope="module")
def robot():
    require_builds()
    with SimRobot("m32d", eeproms=(EEPROM,), trace=False,
                  slaves=[("m128s", 0x10, None), ("m32d", 0x12, None)]) as sim:
        yield sim


@pytest.fixture
def orfa(robot, capsys, monkeypatch):
    """orfa(*argv) on the robot's port: (exit status, stdout, stderr)."""
    return cli_runner(robot.port, capsys, monkeypatch)


def test_version(orfa):
    assert orfa("version") == (0, "protocol 1.1\nboard    m32d (OR-AVR-M32-D)\n", "")
    assert orfa("version", "--addr", "0x10") == (
        0, "protocol 1.1\nboard    m128s (OR-AVR-M128-S) at 0x10\n", "")


def test_drivers_of_the_gateway(orfa):
    assert orfa("drivers") == (0, "\n".join([
        "0xAA: m32d (OR-AVR-M32-D), 7 drivers",
        "UID   driver  version  registers",
        "0000  intro   1.0      0x00-0x01",
        "0020  gpio    1.1      0x02-0x09",
        "0001  spi     1.1      0x0A-0x0B",
        "0040  adc     1.1      0x0C-0x0D",
        "0060  motor   1.1      0x0E-0x11",
        "0031  servo   2.0      0x12-0x13",
        "0002  sys     1.0      0x14-0x15",
        ""]), "")


def test_drivers_of_a_slave(orfa):
    """The M128-S slave at 0x10 of the robot (built with every driver but
    the motors it has none of: `make robot`)."""
    out = "\n".join([
        "0x10: m128s (OR-AVR-M128-S), 6 drivers",
        "UID   driver  version  registers",
        "0000  intro   1.0      0x00-0x01",
        "0021  gpio    1.1      0x02-0x05",
        "0001  spi     1.1      0x06-0x07",
        "0040  adc     1.1      0x08-0x09",
        "0030  servo   2.0      0x0A-0x0B",
        "0002  sys     1.0      0x0C-0x0D",
        ""])
    assert orfa("drivers", "--addr", "0x10") == (0, out, "")
    assert orfa("--7bit", "drivers", "--addr", "0x08") == (0, out.replace("0x10:", "0x08:"), "")
    assert orfa("--addr", "0x12", "drivers")[1].splitlines()[0] == \
        "0x12: m32d (OR-AVR-M32-D), 7 drivers"
    assert orfa("drivers", "--addr", "0x14") == (
        1, "", "orfa: 0x14: " + NACK + "\n")


def test_scan_shows_every_device_in_the_grid(orfa):
    status, out, err = orfa("scan")
    assert (status, err) == (0, "")
    assert out == "\n".join([
        "     0  1  2  3  4  5  6  7  8  9  a  b  c  d  e  f",
        "00:                         08 09 -- -- -- -- -- --",
        "10: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "20: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "30: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "40: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "50: 50 -- -- -- -- 55 -- -- -- -- -- -- -- -- -- --",
        "60: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --",
        "70: -- -- -- -- -- -- -- --",
        "8-bit: 0x10 0x12 0xA0 0xAA (0xAA: the gateway itself)",
        ""])
    assert orfa("--7bit", "scan")[1].splitlines()[-1] == \
        "7-bit: 0x08 0x09 0x50 0x55 (0x55: the gateway itself)"


def test_scan_all_addresses(orfa):
    status, out, err = orfa("scan", "--all")
    lines = out.splitlines()
    assert lines[1] == "00: -- -- -- -- -- -- -- -- 08 09 -- -- -- -- -- --"
    assert lines[8] == "70: -- -- -- -- -- -- -- -- -- -- -- -- -- -- -- --"


def test_write_then_read_the_eeprom(orfa):
    assert orfa("write", "0xA0", "0x20", "0x41", "0x42", "0x43") == (0, "", "")
    assert orfa("read", "0xA0", "0x20", "3") == (0, "0x41 0x42 0x43\n", "")
    assert orfa("read", "0xA0", "0x21") == (0, "0x42\n", "")
    assert orfa("--7bit", "read", "0x50", "0x22") == (0, "0x43\n", "")


def test_read_a_register_of_a_slave(orfa):
    # introspection's count: the M128-S slave at 0x10 has 6 drivers
    assert orfa("write", "0x10", "0x00", "0x00") == (0, "", "")
    assert orfa("read", "0x10", "0x00", "2") == (0, "0x06 0x06\n", "")


def test_transfer(orfa):
    assert orfa("transfer", "w3@0xA0", "0x30", "0x11", "0x22", "w1", "0x30", "r2",
                "w2@0x10", "0", "0", "r1") == (0, "0x11 0x22\n0x06\n", "")
    assert orfa("--7bit", "transfer", "w1@0x50", "0x31", "r1") == (0, "0x22\n", "")


def test_nothing_at_the_address_is_exit_1(orfa):
    assert orfa("read", "0xA2", "0x00") == (
        1, "", "orfa: 0xA2 register 0x00: " + NACK + "\n")
    assert orfa("transfer", "w1@0xA0", "0", "r1@0xB0")[::2] == (
        1, "orfa: transfer: " + NACK + "\n")


def test_a_write_the_gateway_refuses_is_exit_1(orfa):
    # the status register (0x01) cannot be written: ERROR 07 on the gateway itself
    assert orfa("write", "0xAA", "0x01", "0x00") == (
        1, "", "orfa: 0xAA register 0x01: ERROR 07: no ACK for a data byte"
               " (or a local write a driver rejects)\n")


def test_request_prints_every_reply_and_exits_1_on_an_error(orfa):
    assert orfa("request", "V", "S A2 P", "S A0 P") == (
        1, "V1.1\nERROR 06\nSWP\n",
        "orfa: S A2 P: " + NACK + "\n")
    assert orfa("request", "V", "S A0 P") == (0, "V1.1\nSWP\n", "")


def test_console_from_a_pipe(orfa):
    comment = "#" + "c" * 199
    lines = ["V", comment, "S A0 40 41 P", "#" + "d" * 999, "S A0 40 S A1 01 P",
             "V" * 129, "", "   ", "l", "Q", "caf\u00e9"]
    status, out, err = orfa("console", stdin="\n".join(lines) + "\n")
    assert (status, out) == (0, "\n".join([
        "V1.1", "SWAAP", "SWASR41P", "ERROR 04", "LAA", "ERROR 02",
        "host: a request is ASCII text", ""]))
    # each ERROR explained, as `orfa request` explains it
    assert [line.split(": ")[2] for line in err.splitlines()] == ["ERROR 04", "ERROR 02"]
    assert err.startswith("orfa: %s: ERROR 04: " % ("V" * 129)), err
