"""Simulated boards for the protocol suite.

One simulator per board and test module (module scope, for speed); every test
gets it through the `gw` fixture, which checks on entry that the line is idle
and on exit puts back what tests change (local address, clock), so no test
sees another's state. Each simulator has its own temp dir and link path.
"""

import time

import pytest

from orfa import protocol as p
from orfa.gateway import Gateway
from orfa.sim import BOARDS, BUILD_HINT, SimBoard, missing_builds

EEPROM = 0xA0
#: Wall-clock seconds a reply may take (the simulator runs faster than real time).
REPLY_TIMEOUT = 5.0


def require_builds(boards=BOARDS):
    missing = missing_builds(boards)
    if missing:
        pytest.fail("missing %s: %s" % (", ".join(map(str, missing)), BUILD_HINT),
                    pytrace=False)


class Bench:
    """A running simulated board, the open serial port, and helpers."""

    def __init__(self, sim: SimBoard):
        self.sim = sim
        self.board = sim.board
        self.gw = Gateway(sim.port, timeout=REPLY_TIMEOUT)

    def close(self):
        self.gw.close()

    # --- raw bytes ------------------------------------------------------------
    def read_lines(self, count: int, timeout: float = REPLY_TIMEOUT) -> bytes:
        """Exactly `count` CR LF-ended lines, as received."""
        out = bytearray()
        deadline = time.monotonic() + timeout
        for _ in range(count):
            line = bytearray()
            while not line.endswith(b"\r\n"):
                if time.monotonic() > deadline:
                    raise AssertionError("timed out after %r (waiting for %d lines)"
                                         % (bytes(out + line), count))
                line += self.gw.serial.read_until(b"\r\n")
            out += line
        return bytes(out)

    def exchange(self, data: bytes, lines: int) -> bytes:
        """Send raw bytes, return the `lines` reply lines they get."""
        self.gw.send(data)
        return self.read_lines(lines)

    def ask(self, request, end: bytes = b"\n") -> bytes:
        """One request (str or bytes), its reply line exactly as received."""
        if isinstance(request, str):
            request = request.encode("ascii")
        return self.exchange(request + end, 1)

    def assert_silent(self, quiet: float = 0.3):
        extra = self.gw.read_available(quiet)
        assert extra == b"", "unexpected bytes from the board: %r" % extra

    # --- trace ----------------------------------------------------------------
    def mark(self) -> int:
        return self.sim.trace_mark()

    def events(self, since: int, kinds=None):
        return self.sim.trace_events(since, kinds)

    def bus(self, since: int):
        """The bus events since `since`, as ("start",), ("addr", "A0", "ack"), ..."""
        return [(e.kind[4:],) + e.fields for e in self.events(since, ["twi"])]

    # --- the local register map -------------------------------------------------
    def local_ok(self, request: str) -> bytes:
        """A request's reply text that must be a transaction reply."""
        reply = self.ask(request)
        assert reply.startswith(b"S") and reply.endswith(b"P\r\n"), (request, reply)
        return reply[:-2]

    def driver_count(self) -> int:
        reply = self.ask("S AA 00 00 S AB 01 P")
        assert reply[:6] == b"SWAASR" and reply[8:] == b"P\r\n", reply
        return int(reply[6:8], 16)

    def record(self, n: int) -> bytes:
        """Introspection record of driver n, read on its own."""
        reply = self.ask("S AA 00 %02X S AB 06 P" % n)
        assert reply[:6] == b"SWAASR" and reply[18:] == b"P\r\n", (n, reply)
        return bytes.fromhex(reply[6:18].decode())

    def status(self) -> int:
        reply = self.ask("S AA 01 S AB 01 P")
        assert reply[:5] == b"SWASR" and reply[7:] == b"P\r\n", reply
        return int(reply[5:7], 16)

    def eeprom_read(self, addr: int, count: int) -> bytes:
        (_, result) = self.gw.transaction([p.Write(EEPROM, bytes([addr])), p.Read(EEPROM, count)])
        return result.data

    def eeprom_write(self, addr: int, data: bytes) -> None:
        assert self.gw.write(EEPROM, bytes([addr]) + data) == 1 + len(data)

    def restore(self):
        """Put back what tests change; fails if the board does not answer.

        The leading LF ends any line a test left open (its reply, if any, is
        skipped); the three requests after it must then answer in order.
        """
        want = [b"LAA\r\n", b"C0063\r\n", b"V1.1\r\n"]
        self.gw.send(b"\nL AA\nC 00 64\nV\n")
        lines = []
        for _ in range(5):
            lines.append(self.read_lines(1))
            if lines[-3:] == want:
                break
        assert lines[-3:] == want, "the board did not come back: %r" % lines
        assert self.sim.running, self.sim.stderr


@pytest.fixture(scope="module", params=BOARDS)
def bench(request):
    require_builds([request.param])
    sim = SimBoard(request.param, eeproms=(EEPROM,), trace=True)
    sim.start()
    b = Bench(sim)
    try:
        yield b
    finally:
        b.close()
        status = sim.stop()
        assert status == 0, "orfa-sim exited with %r" % status


@pytest.fixture
def board(bench):
    """The module's board, idle and in its default state."""
    assert bench.sim.running, "the simulator died: %s" % bench.sim.stderr
    bench.gw.serial.reset_input_buffer()
    mark = bench.mark()
    yield bench
    bench.restore()
    resets = bench.events(mark, ["reset"])
    assert resets == [], "the MCU reset during the test: %r" % resets
