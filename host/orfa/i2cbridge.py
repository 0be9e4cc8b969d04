"""The gateway as a plain I2C master, under the Python world's two bus
interfaces: orfa.busio (CircuitPython's busio.I2C) and orfa.smbus
(smbus2's SMBus).

What both share: 7-bit addresses (the protocol's 8-bit form is the 7-bit
one shifted left, R/W in bit 0); every transfer one ORFA request, its
frames joined by repeated STARTs under one STOP, as the device would see
it from any other I2C master; a transfer that one request cannot carry
refused with a ValueError (LimitError) before anything is sent, never
split into several; the gateway's refusals as the OSError each interface
raises (`Errnos`). docs/sensors.md has the limits per method.
"""

from __future__ import annotations

import os
from typing import List, NamedTuple, Sequence, Tuple, Union

from . import protocol as p
from .errors import AddressNackError, DataNackError, LimitError, ReplyTimeout
from .gateway import Gateway

#: One frame of a transfer: (7-bit address, bytes to write) or
#: (7-bit address, number of bytes to read).
Part = Tuple[int, Union[bytes, int]]

#: Request characters of a write frame before its data ("S" and the
#: address), of a read frame ("S", address, count), and the final "P".
_WRITE_HEAD, _READ_CHARS, _END = 3, 5, 1
#: Reply characters of a write frame before its "A"s ("SW"), of a read
#: frame before its data ("SR"), and the final "P".
_REPLY_HEAD, _REPLY_END = 2, 1

#: Bytes one request writes in a write frame alone: 2n + 4 <= 128.
MAX_WRITE = (p.MAX_REQUEST_CHARS - _WRITE_HEAD - _END) // 2
#: Bytes one request reads in a read frame alone: 2n + 3 <= 127.
MAX_READ = (p.MAX_REPLY_CHARS - _REPLY_HEAD - _REPLY_END) // 2
#: Bytes written before a repeated START and a read: 2n + 9 <= 128.
MAX_WRITE_THEN_READ = (p.MAX_REQUEST_CHARS - _WRITE_HEAD - _READ_CHARS - _END) // 2


def max_read_after(out: int) -> int:
    """Bytes one request reads after writing `out` bytes to the same
    device (out + 2n + 5 <= 127): 60 after a register byte."""
    return (p.MAX_REPLY_CHARS - 2 * _REPLY_HEAD - _REPLY_END - out) // 2


def request_chars(parts: Sequence[Part]) -> int:
    """Characters of the request for these frames (without spaces)."""
    return sum(_WRITE_HEAD + 2 * len(what) if isinstance(what, (bytes, bytearray))
               else _READ_CHARS for _, what in parts) + _END


def reply_chars(parts: Sequence[Part]) -> int:
    """Characters of the reply text the request gets."""
    return sum(_REPLY_HEAD + (len(what) if isinstance(what, (bytes, bytearray)) else 2 * what)
               for _, what in parts) + _REPLY_END


class Errnos(NamedTuple):
    """The errno an interface gives for: no ACK for an address (ERROR 06),
    no ACK for a data byte or a bus that failed after the address
    (ERROR 07), no reply from the gateway in time."""

    address: int
    data: int
    timeout: int


def check_address(addr) -> int:
    """A 7-bit address, or ValueError."""
    if not isinstance(addr, int) or isinstance(addr, bool) or not 0 <= addr <= 0x7F:
        raise ValueError("an I2C address is 7-bit, 0x00..0x7F, not %r (the protocol's 8-bit"
                         " address is the 7-bit one shifted left)" % (addr,))
    return addr


class Bridge:
    """A gateway (opened here from a port, or one the caller holds) that
    runs transfers of 7-bit frames as single requests."""

    def __init__(self, port_or_gateway, errnos: Errnos, baudrate: int = p.DEFAULT_BAUD,
                 timeout: float = 2.0):
        self.errnos = errnos
        if isinstance(port_or_gateway, Gateway):
            self.gateway = port_or_gateway
            self.owned = False
        elif isinstance(port_or_gateway, (str, os.PathLike)):
            self.gateway = Gateway(os.fspath(port_or_gateway), baudrate=baudrate, timeout=timeout)
            self.owned = True
        else:
            raise TypeError("an ORFA bus takes a port (a path or a pyserial URL) or an"
                            " orfa.Gateway, not %r" % (port_or_gateway,))

    def close(self) -> None:
        """Close the gateway if it was opened here (one passed in stays open)."""
        if self.owned:
            self.gateway.close()

    def check_fits(self, parts: Sequence[Part], what: str, limit: str) -> None:
        """LimitError (a ValueError) if one request cannot carry these
        frames; `limit` says what fits ("writes at most 62 bytes"), for the
        message."""
        n = request_chars(parts)
        if n > p.MAX_REQUEST_CHARS:
            over = "a request of %d characters (the limit is %d)" % (n, p.MAX_REQUEST_CHARS)
        else:
            n = reply_chars(parts)
            if n <= p.MAX_REPLY_CHARS:
                return
            over = "a reply of %d characters (the limit is %d)" % (n, p.MAX_REPLY_CHARS)
        raise LimitError("%s needs %s: one ORFA request %s, and a transfer is never"
                         " split (docs/sensors.md, \"Limits\")" % (what, over, limit))

    def transfer(self, parts: Sequence[Part], what: str, limit: str) -> List[bytes]:
        """Run the frames as one request; the bytes of each read frame, in
        order. `what` names the call in messages, `limit` what fits."""
        for addr, _ in parts:
            check_address(addr)
        self.check_fits(parts, what, limit)
        frames: List[p.Frame] = []
        for addr, data in parts:
            if isinstance(data, (bytes, bytearray)):
                frames.append(p.Write(addr << 1, bytes(data)))
            else:
                frames.append(p.Read(addr << 1, data))
        results = self._run(lambda: self.gateway.transactions([frames])[0], parts[0][0], what)
        return [r.data for r in results if isinstance(r, p.ReadResult)]

    def scan(self, what: str = "scan") -> List[int]:
        """The 7-bit addresses 0x08..0x77 that acknowledge."""
        return self._run(self.gateway.scan, None, what)

    def _run(self, call, addr, what: str):
        where = "" if addr is None else " at 0x%02X" % addr
        try:
            result = call()
        except ReplyTimeout as e:
            raise self._os_error(self.errnos.timeout, "%s%s: no reply from the ORFA gateway"
                                 " on %s (%s)" % (what, where, self.gateway.url, e)) from e
        if isinstance(result, AddressNackError):
            raise self._os_error(self.errnos.address, "%s%s: no ACK for the address (ORFA"
                                 " ERROR 06: no such device, or the bus could not be had)"
                                 % (what, where)) from result
        if isinstance(result, DataNackError):
            raise self._os_error(self.errnos.data, "%s%s: a byte was not acknowledged or the"
                                 " bus failed after the address (ORFA ERROR 07)"
                                 % (what, where)) from result
        if isinstance(result, Exception):
            raise result
        return result

    @staticmethod
    def _os_error(code: int, text: str) -> OSError:
        """OSError(errno, strerror), as both interfaces raise it: `.errno`
        and args[0] are the code (CircuitPython reads args[0])."""
        return OSError(code, "%s: %s" % (os.strerror(code), text))
