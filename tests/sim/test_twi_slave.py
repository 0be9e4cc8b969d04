"""Several boards on one bus: the TWI slave model and clock stretching.

A gateway board (m32d or m128s) and two slave boards running the test
firmware tests/sim/fw/twi_slave_echo.c (an interrupt-driven TWI slave that
keeps what it is written and gives it back; it waits 1500 cycles with TWINT
set before the first byte of every read): an m32d at 0x20 and an m128s at
0x22, plus an EEPROM at 0xA0.
"""

import subprocess

import pytest

from orfa import boardmap
from orfa.gateway import Gateway
from orfa.sim import BOARDS, REPO_ROOT, SimRobot, sim_path

from conftest import REPLY_TIMEOUT, require_builds

ECHO_ELF = REPO_ROOT / "build" / "sim-fw" / "twi_slave_echo.elf"
ECHO = 0x20
ECHO128_ELF = REPO_ROOT / "build" / "sim-fw" / "twi_slave_echo_m128.elf"
ECHO128 = 0x22
ECHO_STRETCH = 1500
#: TWBR/TWSR data addresses of the gateway's MCU (to compute the SCL period).
TWI_REGS = {"m32d": (0x20, 0x21), "m128s": (0x70, 0x71)}


def require_echo():
    require_builds()
    for elf in (ECHO_ELF, ECHO128_ELF):
        if not elf.is_file():
            pytest.fail("missing %s: run `make sim`" % elf, pytrace=False)


class Robot:
    def __init__(self, sim):
        self.sim = sim
        self.gw = Gateway(sim.port, timeout=REPLY_TIMEOUT)
        self.ctl = sim.control

    def ask(self, line: str) -> str:
        return self.gw.request(line)

    def scl_period(self) -> int:
        twbr, twsr = TWI_REGS[self.sim.board]
        br = int(self.ctl.request("peek %d" % twbr), 16)
        ps = int(self.ctl.request("peek %d" % twsr), 16) & 3
        return 16 + 2 * br * 4 ** ps


@pytest.fixture(scope="module", params=BOARDS)
def robot(request):
    require_echo()
    sim = SimRobot(request.param, slaves=[("m32d", ECHO, ECHO_ELF),
                                          ("m128s", ECHO128, ECHO128_ELF)],
                   eeproms=(0xA0,), trace=True, control=True)
    sim.start()
    r = Robot(sim)
    try:
        yield r
    finally:
        r.gw.close()
        assert sim.stop() == 0


def test_write_then_read_back(robot):
    assert robot.ask("S 20 01 02 P") == "SWAAP"
    assert robot.ask("S 21 02 P") == "SR0102P"
    assert robot.ask("S 20 05 06 07 S 21 03 P") == "SWAAASR050607P"
    # the firmware gives its bytes again from the first
    assert robot.ask("S 21 04 P") == "SR05060705P"


def test_two_slaves_keep_apart(robot):
    assert robot.ask("S 20 A1 A2 P") == "SWAAP"
    assert robot.ask("S 22 B1 B2 B3 P") == "SWAAAP"
    assert robot.ask("S 21 02 S 23 03 P") == "SRA1A2SRB1B2B3P"
    # write one, read the other in a single transaction
    assert robot.ask("S 22 C4 S 21 01 S 23 01 P") == "SWASRA1SRC4P"


def test_read_is_stretched_by_the_slave(robot):
    assert robot.ask("S 20 0A 0B P") == "SWAAP"
    mark = robot.sim.trace_mark()
    assert robot.ask("S 21 02 P") == "SR0A0BP"
    period = robot.scl_period()
    events = robot.sim.trace_events(mark, ["twi"])
    kinds = [e.kind for e in events]
    addr = kinds.index("twi addr")
    assert events[addr].fields == ("21", "ack")
    # the slave holds SCL while it prepares the first byte: the master's
    # first read waits, then takes its 9 SCL periods from the release
    stretch, first = events[addr + 1], events[addr + 2]
    assert stretch.kind == "twi stretch" and stretch.fields[0] == "20", events
    assert ECHO_STRETCH <= int(stretch.fields[1]) < ECHO_STRETCH + 400, events
    assert first.kind == "twi read" and first.fields == ("0A", "ack"), events
    assert first.cycle - stretch.cycle == 9 * period
    assert stretch.cycle - int(stretch.fields[1]) >= events[addr].cycle
    longest = max(c for _, a, c in robot.sim.stretches(mark) if a == ECHO)
    assert longest == int(stretch.fields[1])


def test_data_nack_when_the_slave_is_full(robot):
    data = " ".join("%02X" % b for b in range(0x30, 0x41))   # 17 bytes
    mark = robot.sim.trace_mark()
    assert robot.ask("S 20 %s P" % data) == "ERROR 07"
    writes = [e.fields for e in robot.sim.trace_events(mark, ["twi write"])]
    assert writes[-1] == ("40", "nack") and all(w[1] == "ack" for w in writes[:-1])
    # after 0x88 and the STOP it is addressable again, its 16 bytes kept
    assert robot.ask("S 21 02 P") == "SR3031P"


def test_other_devices_and_addresses(robot):
    assert robot.ask("S A0 00 11 22 P") == "SWAAAP"
    assert robot.ask("S A0 00 S A1 02 P") == "SWASR1122P"
    assert robot.ask("S 24 01 P").startswith("ERROR")          # nobody at 0x24
    assert robot.ask("S 20 77 P") == "SWAP"
    assert robot.ask("S 21 01 P") == "SR77P"


def test_no_reset_anywhere(robot):
    assert robot.sim.trace_events(0, ["reset"]) == []


def bus_lines(trace: str):
    return [l for l in trace.splitlines() if " twi " in l]


def run_scheduled(board: str):
    """A fresh robot, a request put on the serial line at a fixed cycle."""
    with SimRobot(board, slaves=[("m32d", ECHO, ECHO_ELF)], trace=True,
                  control=True) as sim:
        ctl = sim.control
        at = 15000000        # the same absolute cycle in every run
        assert ctl.time() < at
        end = ctl.rx(at, b"S 20 0C 0D P\nS 21 02 P\n")
        ctl.wait(end - ctl.time() + 200000)
        return bus_lines(sim.trace_text())


def test_deterministic():
    require_echo()
    first = run_scheduled("m32d")
    assert any("twi read 0D nack" in l for l in first), first
    assert run_scheduled("m32d") == first


@pytest.mark.parametrize("value, why", [
    ("m32d:0x20", "BOARD:ADDR:ELF"),
    ("m32d:0x21:x.elf", "even 8-bit address"),
    ("m32d:0x08:x.elf", "even 8-bit address"),
    ("m32d:0xF0:x.elf", "even 8-bit address"),
    ("z80:0x20:x.elf", "unknown board"),
])
def test_bad_slave_option(value, why):
    require_builds(["m32d"])
    result = subprocess.run([str(sim_path()), "--board", "m32d", "--link", "/nonexistent/tty",
                             "--slave", value, "x.elf"],
                            capture_output=True, text=True, timeout=30)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and why in result.stderr, result.stderr


@pytest.mark.parametrize("addr", [boardmap.ADDRESS_MIN + d for d in (-2, -1, 0, 1)]
                         + [boardmap.ADDRESS_MAX + d for d in (-1, 0, 1, 2)])
def test_slave_addresses_are_the_rule_of_i2c_addr_h(addr):
    """--slave takes the addresses of firmware/i2c_addr.h, as the host does."""
    require_builds(["m32d"])
    result = subprocess.run([str(sim_path()), "--board", "m32d", "--link", "/nonexistent/tty",
                             "--slave", "m32d:0x%02X:x.elf" % addr, "x.elf"],
                            capture_output=True, text=True, timeout=30)
    rule = "even 8-bit address 0x%02X..0x%02X" % (boardmap.ADDRESS_MIN, boardmap.ADDRESS_MAX)
    assert (rule in result.stderr) == (not boardmap.address_ok(addr)), result.stderr


def test_control_reaches_every_board(robot):
    ctl = robot.ctl
    names = ctl.signals()
    assert "A0" in names and "20/A0" in names and "20/D7" in names
    assert "22/G4" in names and "22/servo31" in names
    echo = ctl.slave(ECHO)
    assert echo.signals() == [n for n in names if n.startswith("20/")]
    # a slave's pin, by prefix or through its view; the gateway's is apart
    ctl.drive("20/A5", 1)
    try:
        assert ctl.pin("20/A5") == (1, "in ext")
        assert echo.pin("A5") == (1, "in ext")
        assert ctl.level("20/A5") == 1
        assert ctl.pin("A5")[1] != "in ext"
    finally:
        ctl.drive("20/A5", None)
    assert echo.pin("A5")[1] != "in ext"
    # requests without a signal pick the board with @20
    twar = 0x22
    assert ctl.request("peek @20 %d" % twar) == "%02X" % ECHO
    assert echo.peek(twar) == bytes([ECHO])
    assert echo.stack()["ramend"] == 0x085F
    assert ctl.request("time @20").isdigit()
    assert ctl.slave(ECHO128).peek(0x72) == bytes([ECHO128])     # its TWAR
    for bad in ("peek @30 0", "pin 30/A5", "rx @20 999999999999 00"):
        with pytest.raises(Exception, match="ERR"):
            ctl.request(bad)


def test_vcd_has_every_board():
    require_echo()
    sim = SimRobot("m32d", slaves=[("m32d", ECHO, ECHO_ELF)], trace=False, vcd=True,
                   control=True)
    sim.start()
    try:
        sim.control.drive("20/B1", 1)
        sim.control.wait(20000)
    finally:
        assert sim.stop(keep_dir=True) == 0
    try:
        text = sim.vcd_path.read_text()
    finally:
        import shutil
        shutil.rmtree(sim.dir)
    assert "$scope module board $end" in text and "$scope module board_20 $end" in text
    ids = [line.split()[3] for line in text.splitlines() if line.startswith("$var")
           and line.split()[4] == "20/B1"]
    assert len(ids) == 1
    assert ("1" + ids[0]) in text.split("$enddefinitions")[1].split("$end", 1)[1]
