"""smbus2's `SMBus` on an ORFA gateway, for drivers that take a bus.

    from orfa.smbus import SMBus
    from bmp280 import BMP280                        # Pimoroni's driver

    with SMBus("/dev/ttyUSB0") as bus:
        print(BMP280(i2c_dev=bus).get_temperature())

`SMBus(port_or_gateway)` takes a port (a path or a pyserial URL: the
simulator's link too) or an `orfa.Gateway` the caller holds, where smbus2
takes a bus number. The methods are smbus2's, with its arguments (`force`
is accepted and means nothing here: nothing else shares the address) and
its results; each call is one ORFA request, the SMBus command's write and
read joined by a repeated START as the SMBus specification has them.
`i2c_rdwr` takes smbus2's own `i2c_msg` objects. Errors are those smbus2
raises from Linux's I2C stack (its fault codes): OSError ENXIO for an
address nobody acknowledges, EIO for a refused byte, ETIMEDOUT when the
gateway does not reply, EPROTO for an SMBus block count over 32; smbus2's
own ValueErrors for blocks over 32 bytes; a transfer longer than one ORFA
request carries is a ValueError too (docs/sensors.md, "Limits").
"""

from __future__ import annotations

import ctypes
import errno
from typing import List, Optional, Sequence

from . import protocol as p
from .i2cbridge import MAX_READ, MAX_WRITE, Bridge, Errnos, Part

#: Linux's I2C fault codes (Documentation/i2c/fault-codes), as smbus2 gets them.
ERRNOS = Errnos(address=errno.ENXIO, data=errno.EIO, timeout=errno.ETIMEDOUT)

#: The largest SMBus block (smbus2's I2C_SMBUS_BLOCK_MAX).
I2C_SMBUS_BLOCK_MAX = 32
#: i2c_msg.flags: a read message (Linux's I2C_M_RD); no other flag is supported.
I2C_M_RD = 0x0001


def _byte(name: str, value) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 0xFF:
        raise ValueError("%s is a byte, 0..255, not %r" % (name, value))
    return value


def _word(value) -> bytes:
    """An SMBus word: low byte first."""
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 0xFFFF:
        raise ValueError("an SMBus word is 0..65535, not %r" % (value,))
    return bytes([value & 0xFF, value >> 8])


def _block(data) -> bytes:
    data = bytes(data)
    if len(data) > I2C_SMBUS_BLOCK_MAX:
        raise ValueError("Data length cannot exceed %d bytes" % I2C_SMBUS_BLOCK_MAX)
    return data


class SMBus:
    """smbus2.SMBus on an ORFA gateway; a context manager (close at exit).

    bus: a port or an orfa.Gateway (None: open() it later). baudrate and
    timeout: for a port opened here.
    """

    def __init__(self, bus=None, force: bool = False, *, baudrate: int = p.DEFAULT_BAUD,
                 timeout: float = 2.0):
        self.force = force
        self.baudrate = baudrate
        self.timeout = timeout
        self._bridge: Optional[Bridge] = None
        if bus is not None:
            self.open(bus)

    def open(self, bus) -> None:
        """Open a port (a path or a pyserial URL) or take an orfa.Gateway."""
        if isinstance(bus, int) and not isinstance(bus, bool):
            raise TypeError("an ORFA SMBus takes a port (a path or a pyserial URL) or an"
                            " orfa.Gateway, not the bus number %d" % bus)
        self.close()
        self._bridge = Bridge(bus, ERRNOS, self.baudrate, self.timeout)

    def close(self) -> None:
        """Close a port opened here (a Gateway passed in stays open)."""
        if self._bridge is not None:
            self._bridge.close()
            self._bridge = None

    def __enter__(self) -> "SMBus":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @property
    def gateway(self):
        """The orfa.Gateway underneath."""
        return self._live().gateway

    def _live(self) -> Bridge:
        if self._bridge is None:
            raise OSError(errno.EBADF, "Bad file descriptor: the SMBus is not open")
        return self._bridge

    def _transfer(self, parts: Sequence[Part], what: str,
                  limit: str = "carries every SMBus command") -> List[bytes]:
        return self._live().transfer(parts, what, limit)

    def _command_read(self, addr: int, register: int, count: int, what: str,
                      data: bytes = b"") -> bytes:
        """Write the command byte (and data), repeated START, read `count`."""
        (got,) = self._transfer([(addr, bytes([_byte("register", register)]) + data),
                                 (addr, count)], what)
        return got

    # --- SMBus commands ---------------------------------------------------------------
    def write_quick(self, i2c_addr: int, force: Optional[bool] = None) -> None:
        """The address alone, write bit set (`S<addr>P`)."""
        self._transfer([(i2c_addr, b"")], "write_quick")

    def read_byte(self, i2c_addr: int, force: Optional[bool] = None) -> int:
        (got,) = self._transfer([(i2c_addr, 1)], "read_byte")
        return got[0]

    def write_byte(self, i2c_addr: int, value: int, force: Optional[bool] = None) -> None:
        self._transfer([(i2c_addr, bytes([_byte("value", value)]))], "write_byte")

    def read_byte_data(self, i2c_addr: int, register: int, force: Optional[bool] = None) -> int:
        return self._command_read(i2c_addr, register, 1, "read_byte_data")[0]

    def write_byte_data(self, i2c_addr: int, register: int, value: int,
                        force: Optional[bool] = None) -> None:
        self._transfer([(i2c_addr, bytes([_byte("register", register),
                                          _byte("value", value)]))], "write_byte_data")

    def read_word_data(self, i2c_addr: int, register: int, force: Optional[bool] = None) -> int:
        """A word, low byte first (SMBus)."""
        got = self._command_read(i2c_addr, register, 2, "read_word_data")
        return got[0] | got[1] << 8

    def write_word_data(self, i2c_addr: int, register: int, value: int,
                        force: Optional[bool] = None) -> None:
        self._transfer([(i2c_addr, bytes([_byte("register", register)]) + _word(value))],
                       "write_word_data")

    def process_call(self, i2c_addr: int, register: int, value: int,
                     force: Optional[bool] = None) -> int:
        """Write a word, repeated START, read a word."""
        got = self._command_read(i2c_addr, register, 2, "process_call", _word(value))
        return got[0] | got[1] << 8

    def read_block_data(self, i2c_addr: int, register: int,
                        force: Optional[bool] = None) -> List[int]:
        """An SMBus block read: the device sends the count, then that many
        bytes. The gateway reads a fixed count, so the request reads the
        count byte and 32 bytes (the longest block) and the bytes past the
        block are dropped: a device sees a longer read than from an SMBus
        controller (harmless for register maps; not for a FIFO)."""
        got = self._command_read(i2c_addr, register, 1 + I2C_SMBUS_BLOCK_MAX, "read_block_data")
        return self._block_reply(got, "read_block_data")

    def write_block_data(self, i2c_addr: int, register: int, data: Sequence[int],
                         force: Optional[bool] = None) -> None:
        """Command byte, count, then the bytes (at most 32)."""
        data = _block(data)
        self._transfer([(i2c_addr, bytes([_byte("register", register), len(data)]) + data)],
                       "write_block_data")

    def block_process_call(self, i2c_addr: int, register: int, data: Sequence[int],
                           force: Optional[bool] = None) -> List[int]:
        """Write a block, repeated START, read a block (read as
        read_block_data does)."""
        data = _block(data)
        got = self._command_read(i2c_addr, register, 1 + I2C_SMBUS_BLOCK_MAX,
                                 "block_process_call", bytes([len(data)]) + data)
        return self._block_reply(got, "block_process_call")

    @staticmethod
    def _block_reply(got: bytes, what: str) -> List[int]:
        if got[0] > I2C_SMBUS_BLOCK_MAX:
            raise OSError(errno.EPROTO, "Protocol error: %s: the device sent a block count of"
                          " %d, the most is %d" % (what, got[0], I2C_SMBUS_BLOCK_MAX))
        return list(got[1:1 + got[0]])

    def read_i2c_block_data(self, i2c_addr: int, register: int, length: int,
                            force: Optional[bool] = None) -> List[int]:
        """Command byte, repeated START, `length` bytes (1..32)."""
        if length > I2C_SMBUS_BLOCK_MAX:
            raise ValueError("Desired block length over %d bytes" % I2C_SMBUS_BLOCK_MAX)
        if length < 1:
            raise ValueError("an I2C block read reads 1..%d bytes, not %r"
                             % (I2C_SMBUS_BLOCK_MAX, length))
        return list(self._command_read(i2c_addr, register, length, "read_i2c_block_data"))

    def write_i2c_block_data(self, i2c_addr: int, register: int, data: Sequence[int],
                             force: Optional[bool] = None) -> None:
        """Command byte, then the bytes (at most 32), no count."""
        data = _block(data)
        self._transfer([(i2c_addr, bytes([_byte("register", register)]) + data)],
                       "write_i2c_block_data")

    # --- plain I2C ------------------------------------------------------------------------
    def i2c_rdwr(self, *i2c_msgs) -> None:
        """smbus2's i2c_msg.write/i2c_msg.read messages as one transaction
        (repeated START between them, one STOP): one request; each read
        message's buffer gets its bytes."""
        if not i2c_msgs:
            raise ValueError("i2c_rdwr takes at least one i2c_msg")
        parts: List[Part] = []
        for msg in i2c_msgs:
            if msg.flags & ~I2C_M_RD:
                raise OSError(errno.EOPNOTSUPP, "Operation not supported: i2c_msg flags 0x%04X:"
                              " an ORFA gateway makes plain 7-bit reads and writes" % msg.flags)
            if msg.flags & I2C_M_RD:
                if msg.len < 1:
                    raise ValueError("an i2c_msg.read reads at least 1 byte")
                parts.append((msg.addr, int(msg.len)))
            else:
                parts.append((msg.addr, ctypes.string_at(msg.buf, msg.len) if msg.len else b""))
        got = iter(self._transfer(parts, "i2c_rdwr with %d i2c_msg" % len(parts),
                                  "carries at most %d bytes written or %d read in one"
                                  " message, fewer in several" % (MAX_WRITE, MAX_READ)))
        for msg in i2c_msgs:
            if msg.flags & I2C_M_RD:
                ctypes.memmove(msg.buf, next(got), msg.len)
