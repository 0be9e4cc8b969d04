"""Differential soak: seeded random requests against a simulated gateway,
every reply compared with the reference model (spec_model.py).

The robot: an M32-D gateway (local address AA), a 24C02 EEPROM at A0 and an
M128-S slave board at 0x10 on its bus (the test robot's build, `make robot`).
Requests go out pipelined within the flow rule (docs/protocol.md, "Flow"):
fewer than 256 characters of requests unanswered. The first reply that differs from the model's stops
the run with the seed, the request's index, the request, expected and got.

Used by tests/sim/test_soak.py (a short run in `make test`) and tools/soak.py
(`make soak`, the long one).
"""

from __future__ import annotations

import collections
import re
import time
from dataclasses import dataclass, field
from typing import Callable, Dict, List

import serial

from orfa.boards import BOARD_UIDS
from orfa.sim import REPO_ROOT, SimBoard, firmware_path, slave_firmware_path

from spec_model import F_CPU, BoardModel, Generator, GatewayModel, Record

#: docs/protocol.md, "Flow": a host keeps fewer than 256 characters of requests
#: unanswered.
FLOW_LIMIT = 256
#: Wall seconds without a byte from the board, while replies are due, before giving up.
STALL_TIMEOUT = 30.0


class SoakFailure(AssertionError):
    """A reply differed from the model's, or the board stopped answering or reset."""


@dataclass
class Figures:
    requests: int = 0
    sync_requests: int = 0          # `V`s the runner adds (see _Stream)
    replies: int = 0
    no_reply: int = 0
    errors: Dict[str, int] = field(default_factory=lambda: collections.Counter())
    bytes_sent: int = 0
    bytes_received: int = 0
    sim_seconds: float = 0.0
    wall_seconds: float = 0.0
    reset_checked: bool = False     # RESET registers read 00 at the end

    def report(self) -> str:
        errs = ", ".join("%s: %d" % (k, v) for k, v in sorted(self.errors.items())) or "none"
        rate = self.requests / self.wall_seconds if self.wall_seconds else 0.0
        return "\n".join([
            "requests                 %d (+%d sync V)" % (self.requests, self.sync_requests),
            "replies checked          %d (all equal to the model's)" % self.replies,
            "requests without reply   %d (empty lines, comments)" % self.no_reply,
            "error replies            %s" % errs,
            "bytes sent / received    %d / %d" % (self.bytes_sent, self.bytes_received),
            "simulated seconds        %.2f" % self.sim_seconds,
            "wall seconds             %.2f" % self.wall_seconds,
            "requests/s (wall)        %.1f" % rate,
            "requests/s (simulated)   %.1f" % (self.requests / self.sim_seconds
                                               if self.sim_seconds else 0.0),
            "resets                   %s" % ("none (trace, and RESET 00 on both boards)"
                                             if self.reset_checked else "not checked"),
        ])


def check_no_reset(sim: SimBoard, since: int) -> int:
    """HOOK: the boards must not have reset since trace position `since`;
    returns the new position.

    Today this looks for `reset` / `reset <SS>` events in the simulator's
    trace (docs/simulator.md, Trace). When the reset-cause register lands
    (issue 8, another engineer), plug its check in here as well: read it on
    the gateway (S AA <reg> S AB 01 P) and the slave and expect "no reset
    since power-up" (then re-sync the model's status register, which the
    read changes)."""
    path = sim.trace_path
    with open(path, "rb") as f:
        f.seek(since)
        tail = b""
        pos = since
        while True:
            chunk = f.read(1 << 22)
            if not chunk:
                break
            data = tail + chunk
            cut = data.rfind(b"\n") + 1
            m = re.search(rb"(?m)^(\d+) reset\b.*$", data[:cut])
            if m:
                raise SoakFailure("the MCU reset: trace line %r" % m.group(0).decode())
            tail = data[cut:]
            pos += len(chunk)
    return pos - len(tail)


SYS_UID = 0x0002                      # the sys driver: RESET at its start register


def reset_register(records: List[Record]) -> int:
    for rec in records:
        if rec.uid == SYS_UID:
            return rec.start
    raise SoakFailure("no sys driver (UID 0002) in %r" % (records,))


def read_reset_cause(ser: serial.Serial, addr: int, reg: int) -> int:
    reply = _ask(ser, "S %02X %02X S %02X 01 P" % (addr, reg, addr | 1))
    m = re.fullmatch(rb"SWASR([0-9A-F]{2})P", reply)
    if not m:
        raise SoakFailure("reset cause of %02X (register %02X): %r" % (addr, reg, reply))
    return int(m.group(1), 16)


def _ask(ser: serial.Serial, line: str, timeout: float = 10.0) -> bytes:
    ser.write(line.encode() + b"\n")
    ser.timeout = timeout
    reply = ser.read_until(b"\r\n")
    if not reply.endswith(b"\r\n"):
        raise SoakFailure("no reply to %r (got %r)" % (line, reply))
    return reply[:-2]


def introspect(ser: serial.Serial, addr: int) -> List[Record]:
    """The board's driver records, read once through the gateway."""
    w, r = addr, addr | 1
    reply = _ask(ser, "S %02X 00 00 S %02X 01 P" % (w, r))
    m = re.fullmatch(rb"SWAASR([0-9A-F]{2})P", reply)
    if not m:
        raise SoakFailure("introspection count of %02X: %r" % (addr, reply))
    count = int(m.group(1), 16)
    records = []
    for first in range(1, count + 1, 10):
        k = min(10, count - first + 1)
        reply = _ask(ser, "S %02X 00 %02X S %02X %02X P" % (w, first, r, 6 * k))
        m = re.fullmatch(rb"SWAASR([0-9A-F]+)P", reply)
        if not m or len(m.group(1)) != 12 * k:
            raise SoakFailure("introspection records of %02X: %r" % (addr, reply))
        raw = bytes.fromhex(m.group(1).decode())
        for i in range(k):
            u = raw[6 * i:6 * i + 6]
            records.append(Record(u[0] << 8 | u[1], u[2], u[3], u[4], u[5]))
    return records


def check_facts(board: str, records: List[Record]) -> None:
    """The board's drivers are the static expectation (host/orfa/boards.py),
    maybe with drivers appended after them; registers contiguous from 0."""
    uids = tuple(r.uid for r in records)
    want = BOARD_UIDS[board]
    if uids[:len(want)] != want:
        raise SoakFailure("%s drivers %s, expected %s first" % (
            board, ["%04X" % u for u in uids], ["%04X" % u for u in want]))
    nxt = 0
    for rec in records:
        if rec.start != nxt or rec.count == 0:
            raise SoakFailure("%s: registers not contiguous at %r" % (board, rec))
        nxt = rec.start + rec.count


class _Stream:
    """The generator's requests, with a `V` put in (deterministically, from
    the requests alone) where lines without a reply would otherwise pile up
    so that the host could not tell whether the board had taken them."""

    def __init__(self, gen: Generator):
        self.gen = gen
        self.quiet = 0       # characters of reply-less lines since the last replied one

    def next(self):
        """(request, None), or (the sync V, request) when the reply-less
        lines sent since the last replied one and this request would not fit
        under the flow limit together. A request is
        (line, terminator, expected reply or None, is a sync V)."""
        line, term, reply = self.gen.next()
        n = len(line) + len(term)
        req = (line, term, reply, False)
        # quiet characters plus this request would not fit: a V first, so
        # that there is a reply to wait for
        sync = self.quiet + n >= FLOW_LIMIT - 2
        if sync:
            self.quiet = 0
        self.quiet = self.quiet + n if reply is None else 0
        if sync:
            return ("V", "\n", b"V1.1\r\n", True), req
        return req, None


def run_soak(requests: int, seed: int, long_blank: bool = True,
             log: Callable[[str], None] = print, check_every: int = 5000,
             gateway: str = "m32d", slave: str = "m128s", slave_addr: int = 0x10,
             eeprom: int = 0xA0) -> Figures:
    """Run `requests` random requests (seed `seed`); returns the figures or
    raises SoakFailure with everything needed to repeat the failing case."""
    elf = slave_firmware_path(slave, slave_addr)
    for path in (firmware_path(gateway), elf):
        if not path.is_file():
            raise SoakFailure("missing %s: run `make all-boards robot sim` in %s"
                              % (path, REPO_ROOT))
    sim = SimBoard(gateway, eeproms=(eeprom,), trace=True, control=True,
                   slaves=[(slave, slave_addr, elf)])
    fig = Figures()
    sim.start()
    try:
        ser = serial.serial_for_url(sim.port, baudrate=115200, timeout=10)
        try:
            _soak(sim, ser, fig, requests, seed, long_blank, log, check_every,
                  gateway, slave, slave_addr, eeprom)
        finally:
            ser.close()
    finally:
        status = sim.stop()
    if status != 0:
        raise SoakFailure("orfa-sim exited with %r: %s" % (status, sim.final_stderr))
    return fig


def _soak(sim, ser, fig, requests, seed, long_blank, log, check_every,
          gateway, slave, slave_addr, eeprom) -> None:
    ctl = sim.control
    # a clean line, then the boards' facts, read once
    ser.write(b"\nV\n")
    ser.timeout = 10
    while True:
        got = ser.read_until(b"\r\n")
        if not got.endswith(b"\r\n"):
            raise SoakFailure("the gateway does not answer: %r" % got)
        if got == b"V1.1\r\n":
            break
    local_records = introspect(ser, 0xAA)
    slave_records = introspect(ser, slave_addr)
    check_facts(gateway, local_records)
    check_facts(slave, slave_records)
    # the reset-cause registers: power-on only, then cleared; read again at the end
    resets = {0xAA: reset_register(local_records), slave_addr: reset_register(slave_records)}
    for addr, reg in resets.items():
        cause = read_reset_cause(ser, addr, reg)
        if cause != 0x01:
            raise SoakFailure("board %02X reset cause %02X at the start, want 01 (power-on)"
                              % (addr, cause))
        if _ask(ser, "S %02X %02X FF P" % (addr, reg)) != b"SWAAP":
            raise SoakFailure("could not clear the reset cause of %02X" % addr)
    # back to the state after reset: introspection cursor 0, status OK, register 0
    for addr in (0xAA, slave_addr):
        if _ask(ser, "S %02X 00 00 P" % addr) != b"SWAAP":
            raise SoakFailure("could not reset introspection of %02X" % addr)
    model = GatewayModel(BoardModel(gateway, local_records), BoardModel(slave, slave_records),
                         slave_addr, eeprom)
    stream = _Stream(Generator(model, seed, long_blank))
    log("soak: seed %d, %d requests, %s gateway (%d drivers), %s slave at %02X "
        "(%d drivers), EEPROM at %02X" % (seed, requests, gateway, len(local_records),
                                          slave, slave_addr, len(slave_records), eeprom))

    trace_pos = check_no_reset(sim, 0)
    t_sim0 = ctl.time()
    t_wall0 = time.monotonic()
    pending = collections.deque()     # [index, line, term, expected, chars]
    history = collections.deque(maxlen=8)
    unanswered = 0
    rx = bytearray()
    index = 0          # requests of the generator sent
    queued = []        # what _Stream gave and is not sent yet
    last_rx = time.monotonic()
    next_check = check_every

    def fail(msg: str) -> None:
        recent = "\n".join("    #%s %r -> %r" % (h[0], h[1] + h[2], h[3]) for h in history)
        raise SoakFailure("soak failed: seed %d\n%s\n  requests before it (sent order):\n%s"
                          % (seed, msg, recent))

    while index < requests or pending:
        out = bytearray()
        while index < requests or queued:
            if not queued:
                first, second = stream.next()
                queued = [first] + ([second] if second else [])
            line, term, expected, sync = queued[0]
            data = (line + term).encode("latin-1")
            if unanswered + len(data) >= FLOW_LIMIT:
                break
            queued.pop(0)
            tag = "sync" if sync else index
            if sync:
                fig.sync_requests += 1
            else:
                index += 1
                fig.requests += 1
            pending.append((tag, line, term, expected, len(data)))
            history.append((tag, line, term, expected))
            unanswered += len(data)
            out += data
            if expected is None:
                fig.no_reply += 1
            elif expected.startswith(b"ERROR"):
                fig.errors[expected[:-2].decode()] += 1
        if out:
            ser.write(out)
            fig.bytes_sent += len(out)
        ser.timeout = 0.02 if (index < requests and not out) else 0.2
        chunk = ser.read(ser.in_waiting or 1)
        now = time.monotonic()
        if chunk:
            last_rx = now
            fig.bytes_received += len(chunk)
            rx += chunk
        elif any(p[3] is not None for p in pending) and now - last_rx > STALL_TIMEOUT:
            first = next(p for p in pending if p[3] is not None)
            fail("  no reply for %.0f s; oldest request waiting: #%s %r, expected %r"
                 % (STALL_TIMEOUT, first[0], first[1] + first[2], first[3]))
        elif not any(p[3] is not None for p in pending):
            # only reply-less lines left: the board took them once a later
            # reply came; at the very end nothing more is due
            if index >= requests and not queued:
                break
        while True:
            cut = rx.find(b"\r\n")
            if cut < 0:
                break
            got = bytes(rx[:cut + 2])
            del rx[:cut + 2]
            quiet = []
            while pending and pending[0][3] is None:
                quiet.append(pending.popleft())
                unanswered -= quiet[-1][4]
            quiet_note = "".join(
                "\n  (or a reply to #%s %r, a line that must get none)" % (q[0], q[1] + q[2])
                for q in quiet)
            if not pending:
                fail("  a reply nobody asked for: %r%s" % (got, quiet_note))
            tag, line, term, expected, n = pending.popleft()
            unanswered -= n
            if got != expected:
                fail("  request #%s %r\n  expected %r\n  got      %r%s"
                     % (tag, line + term, expected, got, quiet_note))
            fig.replies += 1
        if fig.requests >= next_check:
            next_check += check_every
            trace_pos = check_no_reset(sim, trace_pos)
            log("soak: %d requests, %d replies checked, %.0f s" % (
                fig.requests, fig.replies, time.monotonic() - t_wall0))
    # the end: one more request must come back next, and nothing else
    ser.write(b"V\n")
    ser.timeout = 10
    got = bytes(rx) + ser.read_until(b"\r\n")
    if got != b"V1.1\r\n":
        fail("  after the last request: expected b'V1.1\\r\\n', got %r" % got)
    fig.sim_seconds = (ctl.time() - t_sim0) / F_CPU
    fig.wall_seconds = time.monotonic() - t_wall0
    check_no_reset(sim, trace_pos)
    # and the boards say so themselves: no reset of any cause since the start
    # (the local address back at AA first: the requests may have moved it)
    if _ask(ser, "LAA") != b"LAA":
        raise SoakFailure("could not set the local address back to AA")
    for addr, reg in resets.items():
        cause = read_reset_cause(ser, addr, reg)
        if cause:
            raise SoakFailure("board %02X reset during the soak: cause %02X" % (addr, cause))
    fig.reset_checked = True
