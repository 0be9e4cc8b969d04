"""A gateway on a serial line: requests out, reply lines back.

The transport is `serial.serial_for_url(url)`, so `loop://`, `socket://`, a
pseudo-terminal path (the simulator's link) and a real port are the same.
"""

from __future__ import annotations

import time
from typing import Callable, Dict, FrozenSet, Iterable, List, Optional, Sequence

import serial

from . import boards
from . import protocol as p


class Gateway:
    """An ORFA gateway on one serial port; a context manager.

    autobaud=True sends the preamble of a BAUD=auto firmware (eight CRs, then
    quiet) right after opening; see preamble().
    """

    def __init__(self, url: str, baudrate: int = p.DEFAULT_BAUD, timeout: float = 2.0,
                 local_address: int = p.DEFAULT_LOCAL_ADDRESS, autobaud: bool = False,
                 wait: Optional[Callable[[float], None]] = None):
        self.timeout = timeout
        self.local = local_address
        self.serial = serial.serial_for_url(url, baudrate=baudrate, timeout=timeout)
        self._sys_reg: Dict[int, int] = {}
        if autobaud:
            self.preamble(wait)

    def preamble(self, wait: Optional[Callable[[float], None]] = None) -> None:
        """Send the autobaud preamble at the port's rate, then stay quiet
        until the firmware listens (SPEC section 2). `wait(seconds)` passes
        that time: a simulator's simulated clock (SimBoard.wait_s); by
        default time.sleep, for a real board. Empty lines to a firmware of
        a fixed rate (no reply)."""
        self.send(p.AUTOBAUD_PREAMBLE)
        (wait or time.sleep)(p.autobaud_wait_s(self.serial.baudrate))

    # --- lifetime -----------------------------------------------------------
    def close(self) -> None:
        self.serial.close()

    def __enter__(self) -> "Gateway":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # --- lines ----------------------------------------------------------------
    def send(self, data: bytes) -> None:
        """Write raw bytes (no checks, no terminator added)."""
        self.serial.write(data)
        self.serial.flush()

    def read_reply(self, timeout: Optional[float] = None) -> str:
        """The next reply line without its CR LF; ReplyTimeout if none comes."""
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        buf = bytearray()
        while not buf.endswith(b"\r\n"):
            left = deadline - time.monotonic()
            if left <= 0:
                raise p.ReplyTimeout("no reply line (got %r)" % bytes(buf))
            chunk = self.serial.read_until(b"\n")
            buf += chunk
            if buf.endswith(b"\n") and not buf.endswith(b"\r\n"):
                raise p.ProtocolError("reply line not ended by CR LF: %r" % bytes(buf))
        return p.strip_reply(bytes(buf))

    def read_available(self, quiet: float = 0.3) -> bytes:
        """Whatever arrives until the line has been quiet for `quiet` seconds."""
        out = bytearray()
        self.serial.timeout = quiet
        try:
            while True:
                chunk = self.serial.read(4096)
                if not chunk:
                    return bytes(out)
                out += chunk
        finally:
            self.serial.timeout = self.timeout

    def request(self, line: str) -> str:
        """Send one request, return its reply text (ERROR replies included)."""
        self.send(p.encode_request(line))
        return self.read_reply()

    def pipeline(self, lines: Sequence[str]) -> List[str]:
        """Send every request in one write, then read one reply per request."""
        data = b"".join(p.encode_request(line) for line in lines)
        self.send(data)
        return [self.read_reply() for _ in lines]

    # --- commands -------------------------------------------------------------
    def version(self) -> str:
        return p.parse_version(self.request(p.format_version()))

    def clear_bus(self) -> None:
        p.parse_clear(self.request(p.format_clear()))

    def local_address(self, new: Optional[int] = None) -> int:
        addr = p.parse_local_address(self.request(p.format_local_address(new)))
        self.local = addr
        return addr

    def clock(self, khz: Optional[int] = None) -> int:
        return p.parse_clock(self.request(p.format_clock(khz)))

    def transaction(self, frames: Sequence[p.Frame]) -> List[p.FrameResult]:
        frames = list(frames)
        line = p.format_transaction(frames)
        return p.parse_transaction(self.request(line), frames)

    def write(self, addr: int, data: Iterable[int] = b"") -> int:
        """Write data to a device; returns the number of acknowledged bytes."""
        (result,) = self.transaction([p.Write(addr, bytes(data))])
        return result.acks

    def probe(self, addr: int) -> bool:
        """True if a device acknowledges its address."""
        try:
            self.write(addr)
        except p.AddressNackError:
            return False
        return True

    def read(self, addr: int, count: int) -> bytes:
        (result,) = self.transaction([p.Read(addr, count)])
        return result.data

    # --- register semantics (docs/registers.md) ---------------------------------
    def write_register(self, addr: Optional[int], reg: int, data: Iterable[int] = b"") -> None:
        """Write data to register reg of addr (None: the gateway itself)."""
        addr = self.local if addr is None else addr
        self.transaction(p.register_write_frames(addr, reg, data))

    def read_register(self, addr: Optional[int], reg: int, count: int) -> bytes:
        """Select register reg of addr (None: the gateway itself), read count bytes."""
        addr = self.local if addr is None else addr
        results = self.transaction(p.register_read_frames(addr, reg, count))
        return results[-1].data

    def drivers(self, addr: Optional[int] = None) -> List[p.DriverRecord]:
        """The introspection records of addr (None: the gateway itself), driver 1 first."""
        addr = self.local if addr is None else addr
        (count,) = self.transaction([p.Write(addr, b"\x00\x00"),
                                     p.Read(addr, 1)])[-1].data
        records: List[p.DriverRecord] = []
        per_read = 10
        for first in range(1, count + 1, per_read):
            n = min(per_read, count + 1 - first)
            data = self.transaction([p.Write(addr, bytes([0x00, first])),
                                     p.Read(addr, 6 * n)])[-1].data
            records += p.DriverRecord.parse_many(data)
        return records

    # --- the sys driver (docs/registers.md "sys") ---------------------------------
    def sys_register(self, addr: Optional[int] = None) -> int:
        """The RESET register of addr's sys driver (FAILSAFE follows it), from
        its introspection record (asked once per address)."""
        addr = self.local if addr is None else addr
        if addr not in self._sys_reg:
            recs = [r for r in self.drivers(addr) if r.uid == boards.SYS_UID]
            if not recs:
                raise p.OrfaError("0x%02X has no sys driver (UID %04X)" % (addr, boards.SYS_UID))
            self._sys_reg[addr] = recs[0].start
        return self._sys_reg[addr]

    def reset_cause(self, addr: Optional[int] = None) -> FrozenSet[str]:
        """Why addr (None: the gateway) reset since the causes were last
        cleared: a set of "power", "external", "brownout", "watchdog", "jtag"."""
        byte = self.read_register(addr, self.sys_register(addr), 1)[0]
        return boards.reset_causes(byte)

    def clear_reset_cause(self, addr: Optional[int] = None,
                          causes: Optional[Iterable[str]] = None) -> None:
        """Forget the reset causes (all, or the names given)."""
        bits = boards.RESET_CAUSES_ALL if causes is None else boards.reset_cause_bits(causes)
        self._sys_write(addr, 0, bytes([bits]))

    def failsafe(self, addr: Optional[int] = None) -> int:
        """The link-loss failsafe's timeout in milliseconds (0: off)."""
        data = self.read_register(addr, self.sys_register(addr) + 1, 2)
        return data[0] << 8 | data[1]

    def set_failsafe(self, addr: Optional[int], ms: int) -> None:
        """Motors stop and servos go limp when no request has reached addr
        (None: the gateway) for `ms` milliseconds; 0 turns it off."""
        if not 0 <= ms <= boards.FAILSAFE_MAX_MS:
            raise ValueError("failsafe: 0..%d ms, not %r" % (boards.FAILSAFE_MAX_MS, ms))
        self._sys_write(addr, 1, bytes([ms >> 8, ms & 0xFF]))

    def _sys_write(self, addr: Optional[int], offset: int, data: bytes) -> None:
        addr = self.local if addr is None else addr
        self.write_register(addr, self.sys_register(addr) + offset, data)
        if addr != self.local:
            # a slave acknowledges before its driver decides: ask it
            status = self.read_register(addr, 0x01, 1)[0]
            if status:
                raise p.OrfaError("0x%02X refused the sys write: status %02X" % (addr, status))

    def status(self) -> int:
        """The gateway's status register (result of the last register access)."""
        return self.read_register(None, 0x01, 1)[0]
