"""The errors a Board raises beyond the protocol's own (orfa.protocol).

Every class here is an OrfaError, so one `except OrfaError` catches all of
them. `Status` is the status register's codes (docs/registers.md "0x01:
status"), names and explanations from the board map.
"""

from __future__ import annotations

import enum
from typing import Dict, Optional, Type

from . import boardmap as _map
from .protocol import OrfaError


class _StatusBase(enum.IntEnum):
    def __str__(self) -> str:
        return self.name

    def __format__(self, spec: str) -> str:
        """The name ("{:>10}"), or the number with a numeric type ("{:02X}")."""
        if spec and spec[-1] in "bcdoxXneEfFgG%":
            return format(int(self), spec)
        return format(self.name, spec)

    @property
    def text(self) -> str:
        """What the code means, as the board map explains it."""
        return _map.STATUS[int(self)].text


#: The status register's codes: Status.PIN_BUSY, Status(3), .name, .text.
Status = _StatusBase("Status", [(s.name, s.code) for s in
                                sorted(_map.STATUS.values(), key=lambda s: s.code)],
                     module=__name__, qualname="Status")


class SerialError(OrfaError):
    """The serial port could not be opened, or failed in use (pyserial's
    SerialException or an OSError, kept as __cause__)."""


class NoDriverError(OrfaError):
    """The board has no such driver (introspection does not list it)."""


class RegisterError(OrfaError):
    """The board refused a register write or read; the status register says why.

    `.status` (Status), `.addr` (the board's 8-bit address), `.register`
    (e.g. "servo SP"). Where the refusal came as an `ERROR 06`/`ERROR 07`
    reply, that error is the __cause__ and its code is `.code`; a slave's
    refusal found only in its status register has no code.
    """

    #: The Status name this class stands for (set by each subclass).
    status_name: str = ""

    def __init__(self, status: int, addr: int, register: str, action: str,
                 code: Optional[int] = None):
        self.status = Status(status)
        self.addr = addr
        self.register = register
        super().__init__("0x%02X %s: %s refused: %s (%s)"
                         % (addr, register, action, self.status.name, self.status.text),
                         code=code)


class BadLengthError(RegisterError):
    status_name = "BAD_LENGTH"


class BadValueError(RegisterError):
    status_name = "BAD_VALUE"


class PinBusyError(RegisterError):
    status_name = "PIN_BUSY"


class NotWritableError(RegisterError):
    status_name = "NOT_WRITABLE"


class NotReadableError(RegisterError):
    status_name = "NOT_READABLE"


class NotBoundError(RegisterError):
    status_name = "NOT_BOUND"


class NoRegisterError(RegisterError):
    status_name = "NO_REGISTER"


class DroppedError(RegisterError):
    """A slave dropped a write frame its master abandoned (docs/protocol.md,
    "Abandoned frames"): nothing of it was applied."""
    status_name = "DROPPED"


#: The RegisterError subclass of each refusing status (OK and READ_WRAPPED
#: are not refusals). A name the map does not have fails here, at import.
REGISTER_ERRORS: Dict[Status, Type[RegisterError]] = {
    Status[cls.status_name]: cls
    for cls in (BadLengthError, BadValueError, PinBusyError, NotWritableError,
                NotReadableError, NotBoundError, NoRegisterError, DroppedError)
}

#: Status codes that are not refusals.
NOT_ERRORS = frozenset((Status.OK, Status.READ_WRAPPED))


def register_error(status: int, addr: int, register: str, action: str,
                   code: Optional[int] = None) -> RegisterError:
    """The exception for a refusal with `status` (a code the map does not
    know gives a plain RegisterError)."""
    try:
        st = Status(status)
    except ValueError:
        err = RegisterError.__new__(RegisterError)
        OrfaError.__init__(err, "0x%02X %s: %s refused: status %02X" % (addr, register, action, status),
                           code=code)
        err.status, err.addr, err.register = status, addr, register
        return err
    cls = REGISTER_ERRORS.get(st, RegisterError)
    return cls(st, addr, register, action, code=code)


def explain(exc: BaseException) -> str:
    """One line for an error: a bare `ERROR xx` gets the code's meaning
    (from the board map, as the firmware's error enum gives it)."""
    text = str(exc) or type(exc).__name__
    code = getattr(exc, "code", None)
    if code is not None and text == "ERROR %02X" % code and code in _map.ERRORS:
        text += ": %s" % _map.ERRORS[code].text
    return text
