"""A board's drivers as Python: `Board` for the gateway's own address or a
slave's, found by introspection, with one client per driver.

    with Board.open("/dev/ttyUSB0") as board:
        board.servo.set_width(3, 1500)
        print(board.adc.volts())

Register numbers come from the board's introspection (each driver's start
register) and the register names of the generated board map (their order
within the driver): nothing here knows a number of its own. Refused writes
and reads raise the RegisterError of the status register's reason
(docs/python.md says what each call sends).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Dict, FrozenSet, Iterable, List, Optional, Sequence, Tuple

from . import boardmap
from . import boards
from . import protocol as p
from .closing import Closing
from .errors import NOT_ERRORS, NoDriverError, Status, register_error
from .gateway import Gateway


#: The driver clients by driver name: board.servo is CLIENTS["servo"](board).
#: The clients sit above the board (each is a layer of register accesses
#: over it): orfa.clients adds them here when it is imported, as orfa does.
CLIENTS: Dict[str, Callable[["Board"], object]] = {}


class _Client:
    """board.<driver>: Board.client(<driver>) as an attribute."""

    def __set_name__(self, owner, name: str) -> None:
        self.name = name

    def __get__(self, board, owner=None):
        return self if board is None else board.client(self.name)


@dataclass(frozen=True)
class Op:
    """One register access of a request: a write of `data`, or a read of
    `count` bytes after a write of `data` (usually empty: a plain select)."""

    kind: str                      # "w" or "r"
    label: str                     # "servo SP", for messages
    reg: int
    data: bytes = b""
    count: int = 0

    @property
    def action(self) -> str:
        return "write" if self.kind == "w" else "read"


class Board(Closing):
    """One ORFA board (the gateway itself, or a slave behind it)."""

    def __init__(self, gateway: Gateway, addr: Optional[int] = None):
        if addr is not None:
            p.Write(addr)                 # checks the address (0..255)
            addr &= 0xFE
        self.gateway = gateway
        self._addr = addr
        self._owns_gateway = False
        self._drivers: Optional[List[p.DriverRecord]] = None
        self._clients: Dict[str, object] = {}

    @classmethod
    def open(cls, url: str, addr: Optional[int] = None, baudrate: int = p.DEFAULT_BAUD,
             timeout: float = 2.0) -> "Board":
        """A Board on its own Gateway(url); closing the board closes the port."""
        board = cls(Gateway(url, baudrate=baudrate, timeout=timeout), addr)
        board._owns_gateway = True
        return board

    def close(self) -> None:
        if self._owns_gateway:
            self.gateway.close()

    def __repr__(self) -> str:
        return "<Board 0x%02X%s>" % (self.addr, " (gateway)" if self.is_local else "")

    # --- identity -------------------------------------------------------------
    @property
    def addr(self) -> int:
        """The board's 8-bit address (the gateway's local address if None was given)."""
        return self.gateway.local if self._addr is None else self._addr

    @property
    def is_local(self) -> bool:
        """True for the gateway's own drivers (no bus in between)."""
        return self._addr is None or self._addr == self.gateway.local & 0xFE

    # --- introspection --------------------------------------------------------
    @property
    def drivers(self) -> List[p.DriverRecord]:
        """The introspection records, read once (refresh() reads again)."""
        if self._drivers is None:
            self.gateway.in_step()
            self._drivers = self.gateway.drivers(self.addr)
        return list(self._drivers)

    def refresh(self) -> None:
        """Forget what introspection said (a board reflashed, reset)."""
        self._drivers = None
        self._clients.clear()

    @property
    def map(self):
        """The generated BoardMap whose driver UIDs match, or None."""
        return boardmap.by_uids([r.uid for r in self.drivers])

    def driver_name(self, uid: int) -> Optional[str]:
        """A UID's driver name ("servo"), None if no board map knows it."""
        hit = boardmap.by_uid(uid)
        return hit[1].name if hit else None

    def _record(self, name: str):
        """(record, BoardMap, DriverMap) of driver `name`; NoDriverError if absent."""
        for rec in self.drivers:
            hit = boardmap.by_uid(rec.uid)
            if hit is not None and hit[1].name == name:
                return rec, hit[0], hit[1]
        raise NoDriverError("0x%02X has no %s driver (its drivers: %s)"
                            % (self.addr, name, ", ".join(
                                self.driver_name(r.uid) or "%04X" % r.uid for r in self.drivers)))

    def has(self, name: str) -> bool:
        try:
            self._record(name)
        except NoDriverError:
            return False
        return True

    def register(self, name: str, reg: str) -> int:
        """Register `reg` of driver `name`: introspection's start plus the
        register's place in the map ("servo", "SP" -> 0x13 on an M32-D)."""
        rec, _, dmap = self._record(name)
        return rec.start + dmap.offset(reg)

    def board_map(self, name: str):
        """The BoardMap the driver `name` of this board comes from (its
        ports, channels)."""
        return self._record(name)[1]

    # --- register access ------------------------------------------------------
    def op_write(self, name: str, reg: str, data: Iterable[int]) -> Op:
        return Op("w", "%s %s" % (name, reg), self.register(name, reg), bytes(data))

    def op_read(self, name: str, reg: str, count: int, select: Iterable[int] = b"") -> Op:
        return Op("r", "%s %s" % (name, reg), self.register(name, reg), bytes(select), count)

    def write(self, name: str, reg: str, data: Iterable[int]) -> None:
        """Write data to a register; RegisterError if the board refuses it."""
        self.execute([[self.op_write(name, reg, data)]])

    def read(self, name: str, reg: str, count: int, select: Iterable[int] = b"") -> bytes:
        """Read count bytes of a register (after writing `select` to it)."""
        return self.execute([[self.op_read(name, reg, count, select)]])[0][0]

    def _status_frames(self) -> List[p.Frame]:
        return p.register_read_frames(self.addr, self.register("intro", "STATUS"), 1)

    def _frames(self, item: Sequence[Op]) -> List[p.Frame]:
        frames: List[p.Frame] = []
        for op in item:
            frames.append(p.Write(self.addr, bytes([op.reg]) + op.data))
            if op.kind == "r":
                frames.append(p.Read(self.addr, op.count))
            if not self.is_local:
                # a slave acknowledges before its driver decides: ask it
                # in the same request (docs/registers.md "On a slave board")
                frames += self._status_frames()
        return frames

    def execute(self, items: Sequence[Sequence[Op]]) -> List[List[bytes]]:
        """Run groups of register accesses, one request per group, all
        pipelined; for each group the data of its reads. On a slave each
        access is followed by a status read in the same request; several
        groups are each followed by a status request, so a refusal's reason
        is the board's own even when later requests ran. The first refusal
        raises (after every group ran)."""
        return self.submit(items).wait()

    def submit(self, items: Sequence[Sequence[Op]]) -> "PendingOps":
        """execute(items) without waiting: the requests join the gateway's
        stream (Gateway.submit) and go out as the flow rule lets them;
        PendingOps.wait() gives what execute() returns (or raises its
        refusal). A robot loop submits its next outputs before it waits
        for the last inputs (docs/python.md, "Pipelining across calls")."""
        items = [list(item) for item in items]
        paired = len(items) > 1
        requests: List[List[p.Frame]] = []
        for item in items:
            requests.append(self._frames(item))
            if paired:
                requests.append(self._status_frames())
        return PendingOps(self, items, paired, self.gateway.submit_transactions(requests))

    def _parse(self, item: Sequence[Op], res) -> Tuple[List[bytes], Optional[p.OrfaError]]:
        reads: List[bytes] = []
        pos = 0
        for op in item:
            pos += 1
            if op.kind == "r":
                reads.append(res[pos].data)
                pos += 1
            if not self.is_local:
                status = res[pos + 1].data[0]
                pos += 2
                if status not in NOT_ERRORS:
                    return reads, register_error(status, self.addr, op.label, op.action)
        return reads, None

    def _refusal(self, item: Sequence[Op], err: p.OrfaError, after) -> p.OrfaError:
        """An ERROR 06/07 reply as the RegisterError of the status register's
        reason (asked now, or the status request run right after)."""
        if not isinstance(err, (p.AddressNackError, p.DataNackError)):
            return err
        if after is None:
            try:
                status = self._read_status()
            except p.OrfaError:
                return err
        elif isinstance(after, p.OrfaError):
            return err
        else:
            status = after[-1].data[0]
        if status in NOT_ERRORS:
            return err
        kind = "w" if isinstance(err, p.DataNackError) else "r"
        op = next((o for o in item if o.kind == kind), item[0])
        refusal = register_error(status, self.addr, op.label, op.action, code=err.code)
        refusal.__cause__ = err
        return refusal

    # --- status, reset cause, failsafe -----------------------------------------
    def _read_status(self) -> int:
        (result,) = self.gateway.transactions([self._status_frames()])
        if isinstance(result, p.OrfaError):
            raise result
        return result[-1].data[0]

    def status(self) -> Status:
        """The status register: the result of the last register access."""
        return Status(self._read_status())

    def reset_cause(self) -> FrozenSet[str]:
        """Why the board reset since the causes were last cleared:
        "power", "external", "brownout", "watchdog", "jtag"."""
        return boards.reset_causes(self.read("sys", "RESET", 1)[0])

    def clear_reset_cause(self, causes: Optional[Iterable[str]] = None) -> None:
        """Forget the reset causes (all, or the names given)."""
        bits = boards.RESET_CAUSES_ALL if causes is None else boards.reset_cause_bits(causes)
        self.write("sys", "RESET", [bits])

    def failsafe(self) -> int:
        """The link-loss failsafe's timeout in ms (0: off)."""
        data = self.read("sys", "FAILSAFE", 2)
        return data[0] << 8 | data[1]

    def set_failsafe(self, ms: int) -> None:
        """Motors stop and servos go limp after `ms` without a request; 0: off."""
        if not isinstance(ms, int) or not 0 <= ms <= boards.FAILSAFE_MAX_MS:
            raise ValueError("failsafe: 0..%d ms, not %r" % (boards.FAILSAFE_MAX_MS, ms))
        self.write("sys", "FAILSAFE", [ms >> 8, ms & 0xFF])

    # --- driver clients -------------------------------------------------------
    def client(self, name: str):
        """The client of driver `name` (CLIENTS), made once; NoDriverError
        if the board has no such driver."""
        if name not in self._clients:
            self._record(name)
            self._clients[name] = CLIENTS[name](self)
        return self._clients[name]

    gpio = _Client()
    servo = _Client()
    motor = _Client()
    adc = _Client()
    spi = _Client()


class PendingOps:
    """Register accesses handed to Board.submit(), under way."""

    def __init__(self, board: Board, items: List[List[Op]], paired: bool, pending):
        self.board = board
        self.items = items
        self.paired = paired
        self.pending = pending

    @property
    def done(self) -> bool:
        return self.pending.done

    def wait(self) -> List[List[bytes]]:
        """For each group the data of its reads, as Board.execute(); the
        first refusal raises."""
        results = self.pending.wait()
        paired = self.paired
        out: List[List[bytes]] = []
        first: Optional[p.OrfaError] = None
        for k, item in enumerate(self.items):
            res = results[2 * k if paired else k]
            if isinstance(res, p.OrfaError):
                after = results[2 * k + 1] if paired else None
                first = first or self.board._refusal(item, res, after)
                out.append([])
                continue
            reads, err = self.board._parse(item, res)
            first = first or err
            out.append(reads)
        if first is not None:
            raise first
        return out


# The board sits above the gateway (docs: host/README.md, "Layers"), so the
# Gateway's board shorthands (gw.board(addr), gw.reset_cause(addr)) make
# their Boards with this class, handed down rather than imported upwards.
Gateway.board_class = Board
