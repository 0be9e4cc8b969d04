"""The manual's C API (host/c, docs/c-library.md) through its example:
`make -C examples` builds examples/get_drivers, which is run on the pty of a
simulated board and robot, and on a pseudo-terminal where a reference model
of the protocol (spec_model.py) plays a gateway whose board has 10 and more
drivers.
What it prints is compared with the board maps (orfa.boardmap, generated
from the C definitions the firmware is built from)."""

import os
import select
import subprocess
import threading
from pathlib import Path

import pytest

from conftest import require_builds, require_slave, running
from orfa import boardmap
from orfa.sim import SimBoard, SimRobot
from spec_model import BoardModel, GatewayModel, Record

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "get_drivers"
PROG_TIMEOUT = 60
M128S, M32D = 0x10, 0x12


@pytest.fixture(scope="module")
def get_drivers():
    r = subprocess.run(["make", "--no-print-directory", "-s", "-C", str(ROOT / "examples")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert EXAMPLE.is_file()

    def run(*args):
        return subprocess.run([str(EXAMPLE)] + [str(a) for a in args], capture_output=True,
                              text=True, timeout=PROG_TIMEOUT)
    return run


def listing(records) -> str:
    """The example's output for these records (docs/c-library.md)."""
    out = ""
    for r in records:
        out += "UID 0x%04X  version %d.%d  registers " % (r.uid, r.major, r.minor)
        if r.count:
            out += "0x%02X-0x%02X (%d)\n" % (r.start, r.start + r.count - 1, r.count)
        else:
            out += "none (0)\n"
    return out


# --- a simulated board and robot -----------------------------------------------

@pytest.mark.parametrize("board", ["m32d", "m128s"])
def test_local_drivers(get_drivers, board):
    require_builds([board])
    want = boardmap.load(board).drivers
    with running(SimBoard(board)) as b:
        for args in ((), ("AA",), ("0xaa",)):
            r = get_drivers(b.sim.port, *args)
            assert (r.returncode, r.stderr) == (0, ""), args
            assert r.stdout == listing(want), args
        assert r.stdout.startswith("UID 0x0000  version 1.0  registers 0x00-0x01 (2)\n")


def test_slave_drivers(get_drivers):
    require_builds(["m32d"])
    slaves = [("m128s", M128S, require_slave("m128s", M128S)),
              ("m32d", M32D, require_slave("m32d", M32D))]
    with running(SimRobot("m32d", slaves=slaves)) as b:
        for board, addr in (("m128s", M128S), ("m32d", M32D)):
            r = get_drivers(b.sim.port, "%02X" % addr)
            assert (r.returncode, r.stderr) == (0, ""), addr
            assert r.stdout == listing(boardmap.load(board).drivers)


def test_a_gateway_at_a_rate_termios_has_no_name_for(get_drivers):
    """BAUD=14400: the library sets the PC's port by number (termios2), the
    simulator's line runs at what the port says, the example reads the list."""
    from conftest import build_gateway
    require_builds(["m32d"])
    sim = SimBoard("m32d", firmware=build_gateway("m32d", 14400), trace=False).start()
    try:
        r = subprocess.run([str(EXAMPLE), sim.port], capture_output=True, text=True,
                           timeout=PROG_TIMEOUT, env=dict(os.environ, ORFA_BAUD="14400"))
        assert (r.returncode, r.stderr) == (0, "")
        assert r.stdout == listing(boardmap.load("m32d").drivers)
    finally:
        sim.stop()


@pytest.mark.parametrize("board, rate", [("m32d", 230400), ("m32d", 460800), ("m128s", 460800)])
def test_a_gateway_at_the_fast_rates(get_drivers, board, rate):
    """ORFA_BAUD=230400/460800: B230400 and B460800 (termios's names)."""
    from conftest import build_gateway
    require_builds([board])
    sim = SimBoard(board, firmware=build_gateway(board, rate), trace=False).start()
    try:
        r = subprocess.run([str(EXAMPLE), sim.port], capture_output=True, text=True,
                           timeout=PROG_TIMEOUT, env=dict(os.environ, ORFA_BAUD=str(rate)))
        assert (r.returncode, r.stderr) == (0, "")
        assert r.stdout == listing(boardmap.load(board).drivers)
    finally:
        sim.stop()


@pytest.mark.parametrize("value", ["fast", "0", "-9600", "9600x"])
def test_bad_orfa_baud(get_drivers, value):
    r = subprocess.run([str(EXAMPLE), "/nonexistent/tty"], capture_output=True, text=True,
                       timeout=PROG_TIMEOUT, env=dict(os.environ, ORFA_BAUD=value))
    assert (r.returncode, r.stdout) == (2, "")
    assert r.stderr == ("get_drivers: bad ORFA_BAUD '%s': the gateway's rate in bits per"
                        " second (115200)\n" % value)


def leave_in_the_board(b, data: bytes) -> None:
    """A program writes `data` to the board's port and closes it: decided in
    simulated time, once the simulator has taken every byte from the port."""
    ctl = b.sim.control
    before = ctl.line()["pty"]
    fd = os.open(b.sim.port, os.O_RDWR | os.O_NOCTTY)
    try:
        os.write(fd, data)
        ctl.wait_taken(before + len(data))
    finally:
        os.close(fd)


@pytest.mark.parametrize("held", ["S AA 0", "SAA0000SAB01", "V", "# a comment"])
def test_partial_line_left_in_the_board(get_drivers, held):
    """Someone typed part of a line in a terminal and closed it: the board
    holds it. The library's open ends it and drops its reply, so the first
    request is answered as itself (it was ERROR 03, glued to the partial
    line)."""
    require_builds(["m32d"])
    with running(SimBoard("m32d", control=True)) as b:
        leave_in_the_board(b, held.encode())
        r = get_drivers(b.sim.port)
        assert (r.returncode, r.stderr) == (0, "")
        assert r.stdout == listing(boardmap.load("m32d").drivers)
        assert b.gw.version() == "1.1"


def test_a_held_request_without_its_line_end_does_not_run(get_drivers):
    """A whole request lacking only its line end (`S A0 10 77 P`, an EEPROM
    write) is ended by the open as an error: nothing of it runs."""
    require_builds(["m32d"])
    with running(SimBoard("m32d", eeproms=(0xA0,), control=True)) as b:
        leave_in_the_board(b, b"S A0 10 77 P")
        r = get_drivers(b.sim.port)
        assert (r.returncode, r.stderr) == (0, "")
        assert b.ask("S A0 10 S A1 01 P") == b"SWASRFFP\r\n"


def test_error_reply(get_drivers):
    """No device at 0x42: the gateway's ERROR 06, one line, exit 1."""
    require_builds(["m32d"])
    with running(SimBoard("m32d")) as b:
        r = get_drivers(b.sim.port, "42")
        assert r.returncode == 1
        assert r.stdout == ""
        assert r.stderr == ("get_drivers: %s: address 0x42: ERROR 06 (%s)\n"
                            % (b.sim.port, boardmap.ERRORS[6].text))
        # the board is fine after it
        assert b.gw.version() == "1.1"


def test_missing_port(get_drivers):
    r = get_drivers("/nonexistent/tty")
    assert r.returncode == 1
    assert r.stdout == ""
    assert r.stderr == "get_drivers: /nonexistent/tty: No such file or directory\n"


@pytest.mark.parametrize("args", [(), ("a", "b", "c"), ("",)])
def test_usage(get_drivers, args):
    r = get_drivers(*args)
    assert r.returncode == 2
    assert r.stderr.startswith("usage: get_drivers PORT [ADDRESS]") and r.stderr.count("\n") == 1


@pytest.mark.parametrize("address", ["11", "zz", "100", "-2", "0x", "AA "])
def test_bad_address(get_drivers, address):
    """Refused before the port is opened (the port does not exist here)."""
    r = get_drivers("/nonexistent/tty", address)
    assert r.returncode == 2
    assert r.stderr.startswith("get_drivers: bad address '%s'" % address)
    assert r.stderr.count("\n") == 1


# --- a gateway with many drivers: the model on a pseudo-terminal ------------------

class FakeGateway:
    """The protocol's reference model answering on the master side of a pty:
    it answers only when the host has gone quiet (QUIET s), so a host that
    sends more than the gateway's receive ring holds is caught
    (`most_unanswered`)."""

    QUIET = 0.05

    def __init__(self, ndrivers: int = 0, records=None):
        if records is None:
            records = [Record(0x0000, 1, 0, 0x00, 2)]
            start = 2
            for i in range(1, ndrivers):
                records.append(Record(0x0100 + i, 1 + i % 3, i % 10, start, 1))
                start += 1
        self.records = records
        self.model = GatewayModel(BoardModel("m32d", records), BoardModel("m32d", records[:1]),
                                  slave_addr=0x10)
        self.master, slave = os.openpty()
        self.path = os.ttyname(slave)
        self.slave = slave
        self.requests = []
        self.replies = []
        self.most_unanswered = 0
        self.stop = False
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        buf = b""
        while not self.stop:
            ready, _, _ = select.select([self.master], [], [], self.QUIET)
            if ready:
                try:
                    buf += os.read(self.master, 4096)
                except OSError:
                    buf = b""
                continue
            # quiet: answer every whole line received
            self.most_unanswered = max(self.most_unanswered, len(buf))
            while b"\n" in buf:
                line, buf = buf.split(b"\n", 1)
                reply = self.model.reply(line.decode("ascii"))
                if reply is None:
                    continue
                self.requests.append(line.decode("ascii"))
                self.replies.append(reply)
                os.write(self.master, reply)

    def close(self):
        self.stop = True
        self.thread.join(5)
        os.close(self.master)
        os.close(self.slave)



def drivers_of(get_drivers, fake):
    """get_drivers run against a scripted gateway `fake`, which is closed
    after: (fake, its result)."""
    try:
        return fake, get_drivers(fake.path)
    finally:
        fake.close()

@pytest.mark.parametrize("ndrivers", [1, 9, 10, 11, 20, 200])
def test_many_drivers(get_drivers, ndrivers):
    fake, r = drivers_of(get_drivers, FakeGateway(ndrivers))
    assert (r.returncode, r.stderr) == (0, "")
    assert r.stdout == listing(fake.records)
    # the count, then the records ten at a time from driver 1: never a read
    # of 0 bytes (ERROR 04), ten records in exactly the 127-character reply
    full, rest = divmod(ndrivers, 10)
    # the open's `!` (an error line on purpose: it ends a partial line), V, L
    want = ["!", "V", "L", "SAA0000SAB01P"]
    want += ["SAA00%02XSAB3CP" % (10 * i + 1) for i in range(full)]
    if rest:
        want.append("SAA00%02XSAB%02XP" % (10 * full + 1, 6 * rest))
    assert fake.requests == want
    assert fake.replies[0] == b"ERROR 02\r\n"
    assert all(not reply.startswith(b"ERROR") for reply in fake.replies[1:])
    for req, reply in zip(want[3:], fake.replies[3:]):
        if req.endswith("3CP"):
            assert len(reply) == 127 + 2, reply
    # the flow rule (docs/protocol.md): never more requests unanswered than the
    # ring holds
    assert fake.most_unanswered <= 252, fake.most_unanswered
    if ndrivers == 200:
        # 21 requests of 14 characters: the library had to wait for replies
        assert fake.most_unanswered > 14 * 10


def test_eeprom_is_not_an_orfa_board(get_drivers):
    """A device that answers but is no ORFA board (the simulated bus's
    24C02 at A0, blank: every byte FF): one line saying so, nothing on
    stdout, exit 1 (it printed 255 records of FF and exited 0)."""
    require_builds(["m32d"])
    with running(SimBoard("m32d", eeproms=(0xA0,))) as b:
        r = get_drivers(b.sim.port, "A0")
        assert (r.returncode, r.stdout) == (1, "")
        assert r.stderr == ("get_drivers: %s: address 0xA0: not an ORFA board: driver 1 is"
                            " UID 0xFFFF with registers from 0xFF (255), not introspection"
                            " (UID 0x0000, registers 0x00-0x01)\n" % b.sim.port)


I = Record(0x0000, 1, 0, 0x00, 2)


@pytest.mark.parametrize("records, why", [
    ([Record(0x0000, 1, 0, 0x00, 3)],
     "driver 1 is UID 0x0000 with registers from 0x00 (3), not introspection"
     " (UID 0x0000, registers 0x00-0x01)"),
    ([I, Record(0x0101, 1, 1, 0x02, 8), Record(0x0102, 1, 1, 0x0B, 2)],
     "driver 3's registers start at 0x0B, not at 0x0A where driver 2's end"),
    ([I, Record(0x0101, 1, 1, 0x02, 8), Record(0x0102, 1, 1, 0x08, 2)],
     "driver 3's registers start at 0x08, not at 0x0A where driver 2's end"),
    ([I, Record(0x0101, 1, 1, 0x02, 0xF0), Record(0x0102, 1, 1, 0xF2, 0x0F)],
     "driver 3's registers run past 0xFF (0xF2-0x100)"),
    ([I, Record(0x0101, 1, 1, 0x02, 8), Record(0x0000, 1, 0, 0x0A, 2)],
     "driver 3 has UID 0x0000, introspection's"),
], ids=["intro-size", "gap", "overlap", "past-FF", "second-intro"])
def test_implausible_driver_list(get_drivers, records, why):
    """The reference model serving a driver list that breaks one rule of the
    layout (a driver 1 that is not introspection: the EEPROM test above)."""
    fake, r = drivers_of(get_drivers, FakeGateway(records=records))
    assert (r.returncode, r.stdout) == (1, "")
    assert r.stderr == "get_drivers: %s: address 0xAA: not an ORFA board: %s\n" % (fake.path, why)


def test_plausible_edges(get_drivers):
    """What a board may have: a driver with no registers, registers up to 0xFF."""
    records = [I, Record(0x0101, 1, 1, 0x02, 0), Record(0x0102, 1, 1, 0x02, 0xFE)]
    fake, r = drivers_of(get_drivers, FakeGateway(records=records))
    assert (r.returncode, r.stderr) == (0, "")
    assert r.stdout == listing(records)


def test_no_reply(get_drivers):
    """A port where nothing answers: one line, exit 1, after the timeout."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    try:
        r = get_drivers(path)
    finally:
        os.close(master)
        os.close(slave)
    assert r.returncode == 1
    assert r.stdout == ""
    assert r.stderr == "get_drivers: %s: address 0xAA: no reply in time\n" % path


def test_docs_sample_is_the_m32d_map():
    """docs/c-library.md shows get_drivers' output for an M32-D: it must be
    what the program prints for the board map as it is."""
    doc = (ROOT / "docs" / "c-library.md").read_text()
    shown = "".join(line[4:] + "\n" for line in doc.splitlines() if line.startswith("    UID "))
    assert shown == listing(boardmap.load("m32d").drivers)


# --- the docs' build instructions -------------------------------------------------

def _doc() -> str:
    return (ROOT / "docs" / "c-library.md").read_text()


def test_docs_build_line_builds_a_program(tmp_path):
    """The `cc` line of docs/c-library.md's Build section, as written, run
    from the repository root with the example's source as `myprog.c`: it
    compiles and links (it once lacked host/c/orfa_speed.c), and the program
    runs."""
    import shlex
    lines = [line.strip() for line in _doc().splitlines() if line.strip().startswith("cc ")]
    assert len(lines) == 1, lines
    args = shlex.split(lines[0])
    assert "myprog.c" in args and args[args.index("-o") + 1] == "myprog", args
    prog = tmp_path / "myprog"
    args = [str(ROOT / "examples" / "get_drivers.c") if a == "myprog.c" else a for a in args]
    args[args.index("-o") + 1] = str(prog)
    r = subprocess.run(args, cwd=str(ROOT), capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    r = subprocess.run([str(prog)], capture_output=True, text=True, timeout=PROG_TIMEOUT)
    assert r.returncode == 2 and r.stderr.startswith("usage: get_drivers PORT")


def test_docs_file_table_lists_every_library_file():
    """Every file of host/c is in the docs' table of the library's files, and
    every .c file of it is on the build line."""
    doc = _doc()
    table = [line for line in doc.splitlines() if line.startswith("| `host/c/")]
    build = [line for line in doc.splitlines() if line.strip().startswith("cc ")]
    for f in sorted((ROOT / "host" / "c").iterdir()):
        assert any("`%s`" % f.name in row or "`host/c/%s`" % f.name in row for row in table), f.name
        if f.suffix == ".c":
            assert "host/c/%s" % f.name in build[0], f.name
