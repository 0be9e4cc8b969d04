"""CircuitPython's `busio.I2C` on an ORFA gateway, for Adafruit's drivers.

    from orfa.busio import I2C
    import adafruit_mpu6050

    with I2C("/dev/ttyUSB0") as i2c:
        mpu = adafruit_mpu6050.MPU6050(i2c)          # 7-bit 0x68: ORFA's D0
        print(mpu.acceleration)

`I2C(port_or_gateway)` takes a port (a path or a pyserial URL: the
simulator's link too) or an `orfa.Gateway` the caller holds. It needs no
Blinka and no board detection. The semantics are CircuitPython's: the lock
(`try_lock`/`unlock`) before any transfer, 7-bit addresses, buffer slices
by `start`/`end` without copying, `writeto_then_readfrom` as one
transaction with a repeated START (the same bytearray may be both
buffers), `OSError` with CircuitPython's errno when a device does not
answer: ENODEV for an address nobody acknowledges (what Adafruit's
`I2CDevice` probe catches), EIO for a refused byte, ETIMEDOUT when the
gateway does not reply. A transfer longer than one ORFA request carries is
a ValueError (docs/sensors.md, "Limits").
"""

from __future__ import annotations

import errno
import threading
from typing import List, Optional

from . import protocol as p
from .i2cbridge import (MAX_READ, MAX_WRITE, MAX_WRITE_THEN_READ, Bridge, Errnos,
                        max_read_after)

#: What CircuitPython's ports raise (mp_raise_OSError with these codes).
ERRNOS = Errnos(address=errno.ENODEV, data=errno.EIO, timeout=errno.ETIMEDOUT)


def _window(buffer, start: int, end: Optional[int], writable: bool) -> memoryview:
    """buffer[start:end] as a byte view, without copying (the bounds as a
    slice's: negative ones count from the end, out-of-range ones are clipped)."""
    view = memoryview(buffer)
    if view.format != "B" or view.ndim != 1:
        view = view.cast("B")
    if writable and view.readonly:
        raise TypeError("the buffer to read into must be writable (a bytearray),"
                        " not %s" % type(buffer).__name__)
    return view[start:end]


class I2C:
    """busio.I2C on an ORFA gateway; a context manager (deinit at exit).

    frequency (Hz): sets the gateway's bus clock to the fastest rate the
    TWI makes not above it (`C`); None (the default) leaves it as it is
    (100 kHz after reset). baudrate and timeout: for the port opened here.
    """

    def __init__(self, port_or_gateway, *, frequency: Optional[int] = None,
                 baudrate: int = p.DEFAULT_BAUD, timeout: float = 2.0):
        self._bridge: Optional[Bridge] = Bridge(port_or_gateway, ERRNOS, baudrate, timeout)
        self._lock = threading.Lock()
        self._locked = False
        if frequency is not None:
            try:
                self._bridge.gateway.clock(self._khz(frequency))
            except BaseException:
                self.deinit()
                raise

    @staticmethod
    def _khz(frequency) -> int:
        if not isinstance(frequency, int) or not 1000 <= frequency <= 0xFFFF * 1000:
            raise ValueError("frequency is 1000..65535000 Hz, not %r" % (frequency,))
        return frequency // 1000

    @property
    def gateway(self):
        """The orfa.Gateway underneath."""
        return self._live().gateway

    # --- lifetime ----------------------------------------------------------------
    def deinit(self) -> None:
        """Release the gateway: a port opened here is closed, a Gateway
        passed in stays open. Every later call but deinit raises ValueError."""
        if self._bridge is not None:
            self._bridge.close()
            self._bridge = None
        if self._locked:
            self._locked = False
            self._lock.release()

    def __enter__(self) -> "I2C":
        return self

    def __exit__(self, *exc) -> None:
        self.deinit()

    def _live(self) -> Bridge:
        if self._bridge is None:
            raise ValueError("Object has been deinitialized.")
        return self._bridge

    def _locked_bridge(self) -> Bridge:
        bridge = self._live()
        if not self._locked:
            raise RuntimeError("Function requires lock")
        return bridge

    # --- the lock ------------------------------------------------------------------
    def try_lock(self) -> bool:
        """Take the lock; False if it is held already."""
        self._live()
        if not self._lock.acquire(blocking=False):
            return False
        self._locked = True
        return True

    def unlock(self) -> None:
        """Release the lock (nothing if it is not held)."""
        self._live()
        if self._locked:
            self._locked = False
            self._lock.release()

    # --- transfers -------------------------------------------------------------------
    def scan(self) -> List[int]:
        """The 7-bit addresses 0x08..0x77 that acknowledge (one probe each,
        `S<addr>P`, pipelined)."""
        return self._locked_bridge().scan()

    def writeto(self, address: int, buffer, *, start: int = 0, end: Optional[int] = None) -> None:
        """Write buffer[start:end] to the device, then STOP. An empty
        write is an address probe (`S<addr>P`)."""
        bridge = self._locked_bridge()
        data = bytes(_window(buffer, start, end, False))
        bridge.transfer([(address, data)], "writeto of %d bytes" % len(data),
                        "writes at most %d bytes" % MAX_WRITE)

    def readfrom_into(self, address: int, buffer, *, start: int = 0,
                      end: Optional[int] = None) -> None:
        """Read len(buffer[start:end]) bytes from the device into that slice."""
        bridge = self._locked_bridge()
        window = _window(buffer, start, end, True)
        if len(window) == 0:
            raise ValueError("Buffer must be at least length 1")
        (data,) = bridge.transfer([(address, len(window))],
                                  "readfrom_into of %d bytes" % len(window),
                                  "reads at most %d bytes" % MAX_READ)
        window[:] = data

    def writeto_then_readfrom(self, address: int, out_buffer, in_buffer, *,
                              out_start: int = 0, out_end: Optional[int] = None,
                              in_start: int = 0, in_end: Optional[int] = None) -> None:
        """Write out_buffer[out_start:out_end], repeated START, read into
        in_buffer[in_start:in_end]: one transaction, one request. The
        bytes to write are taken before anything is read, so the two may
        be the same buffer."""
        bridge = self._locked_bridge()
        out = bytes(_window(out_buffer, out_start, out_end, False))
        window = _window(in_buffer, in_start, in_end, True)
        if len(window) == 0:
            raise ValueError("Buffer must be at least length 1")
        limit = "writes at most %d bytes before a read" % MAX_WRITE_THEN_READ
        if len(out) <= MAX_WRITE_THEN_READ:
            limit += " and reads at most %d after %d written" % (max_read_after(len(out)),
                                                                 len(out))
        (data,) = bridge.transfer([(address, out), (address, len(window))],
                                  "writeto_then_readfrom of %d bytes out and %d in"
                                  % (len(out), len(window)), limit)
        window[:] = data
