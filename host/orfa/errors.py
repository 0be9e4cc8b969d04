"""Every error of the orfa package, in one tree rooted in OrfaError.

One `except OrfaError` catches each error the package raises for a problem
of the user's, the line's or the board's: an `ERROR xx` reply, a reply the
protocol does not allow, a refused register access, a serial port that
fails, a simulator that cannot start or refuses a control request, a file
that is not what it should be, a wrong command line or dashboard control.
A wrong argument to a function (a channel out of range) stays a
ValueError or TypeError, as Python has it: a bug of the calling program.

The codes come from the board map, generated from the C: `ErrorCode` is
the protocol's `ERROR xx` codes with the firmware's names (SG_ERR_* in
serialgate/sg_parse.h: NO_P, ADDR_NACK, ...), `Status` the status
register's (docs/registers.md "0x01: status"); each class of a code takes
its docstring from the map's text of that code.

The modules that raise an error also export it (orfa.protocol.OrfaError,
orfa.sim.SimError, orfa.cli.common.UsageError, ...), so every name is
found where it always was.
"""

from __future__ import annotations

import enum
import re
from typing import Dict, Optional, Type

from . import boardmap as _map


class _MapCode(enum.IntEnum):
    """An enum of codes from the board map: str() is the name."""

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
        return _CODES[type(self).__name__][int(self)].text


_CODES = {"ErrorCode": _map.ERRORS, "Status": _map.STATUS}


def _map_enum(name: str) -> Type[_MapCode]:
    return _MapCode(name, [(c.name, c.code) for c in
                           sorted(_CODES[name].values(), key=lambda c: c.code)],
                    module=__name__, qualname=name)


#: The protocol's `ERROR xx` codes, named as the firmware names them:
#: ErrorCode.NO_P, ErrorCode(6).name == "ADDR_NACK", .text.
ErrorCode = _map_enum("ErrorCode")
#: The status register's codes: Status.PIN_BUSY, Status(3), .name, .text.
Status = _map_enum("Status")


class OrfaError(Exception):
    """Root of every error of this package; `.code` is the protocol's code."""

    code: Optional[int] = None

    def __init__(self, message: str = "", code: Optional[int] = None):
        if code is not None:
            self.code = code
        super().__init__(message or self._default_message())

    def _default_message(self) -> str:
        if self.code is None:
            return type(self).__name__
        return "ERROR %02X" % self.code


# --- the protocol's ERROR replies and other replies --------------------------

class _ReplyError(OrfaError):
    """An `ERROR xx` reply (one subclass per code, from _reply_error)."""


def _reply_error(name: str, code: ErrorCode) -> Type[_ReplyError]:
    """The class of `code`'s reply, its docstring the map's text of the code."""
    doc = "ERROR %02X (%s): %s." % (code, code.name, code.text)
    return type(name, (_ReplyError,), {"code": code, "__doc__": doc, "__module__": __name__})


InternalError = _reply_error("InternalError", ErrorCode.INTERNAL)
UnknownCommandError = _reply_error("UnknownCommandError", ErrorCode.COMMAND)
HexError = _reply_error("HexError", ErrorCode.HEX)
DataError = _reply_error("DataError", ErrorCode.DATA)
IncompleteError = _reply_error("IncompleteError", ErrorCode.NO_P)
AddressNackError = _reply_error("AddressNackError", ErrorCode.ADDR_NACK)
DataNackError = _reply_error("DataNackError", ErrorCode.DATA_NACK)


class LimitError(DataError, ValueError):
    """Refused on the host: the board would answer ERROR 04 (over a limit)."""


#: The class of each code's `ERROR xx` reply (tests/host/test_boardmap.py
#: checks that every code of the map has one).
ERRORS_BY_CODE: Dict[int, Type[OrfaError]] = {
    cls.code: cls for cls in _ReplyError.__subclasses__()}


def error_for_code(code: int) -> OrfaError:
    """The exception for an `ERROR <code>` reply (unknown codes: OrfaError)."""
    cls = ERRORS_BY_CODE.get(code)
    if cls is None:
        return OrfaError("ERROR %02X" % code, code=code)
    return cls()


class ProtocolError(OrfaError):
    """A reply that is not what the protocol allows (or no reply at all)."""


class ReplyTimeout(ProtocolError):
    """No complete reply line arrived in time."""


# --- the line, the board ------------------------------------------------------

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
    refusal found only in its status register has no code. Each subclass
    stands for the status its name says (BadValueError: BAD_VALUE).
    """

    #: The Status name this class stands for (a subclass's, from its name).
    status_name: str = ""

    def __init_subclass__(cls, **kw):
        super().__init_subclass__(**kw)
        name = "_".join(re.findall(r"[A-Z][a-z]*", cls.__name__[:-len("Error")])).upper()
        if name in Status.__members__:
            cls.status_name = name
            if cls.__doc__ is None:
                cls.__doc__ = "%s: %s." % (name, Status[name].text)

    def __init__(self, status: int, addr: int, register: str, action: str,
                 code: Optional[int] = None):
        self.status = Status(status)
        self.addr = addr
        self.register = register
        super().__init__("0x%02X %s: %s refused: %s (%s)"
                         % (addr, register, action, self.status.name, self.status.text),
                         code=code)


class BadLengthError(RegisterError):
    pass


class BadValueError(RegisterError):
    pass


class PinBusyError(RegisterError):
    pass


class NotWritableError(RegisterError):
    pass


class NotReadableError(RegisterError):
    pass


class NotBoundError(RegisterError):
    pass


class NoRegisterError(RegisterError):
    pass


class DroppedError(RegisterError):
    """A slave dropped a write frame its master abandoned (docs/protocol.md,
    "Abandoned frames"): nothing of it was applied."""


#: The RegisterError subclass of each refusing status (OK and READ_WRAPPED
#: are not refusals). A name the map does not have fails here, at import.
REGISTER_ERRORS: Dict[Status, Type[RegisterError]] = {
    Status[cls.status_name]: cls for cls in RegisterError.__subclasses__()}

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


# --- the simulator, files, the tools ----------------------------------------------

class SimError(OrfaError, RuntimeError):
    """The simulator could not be started or died (orfa.sim). `.refused`:
    the simulator's own one-line reason when it refused its arguments (exit
    status 2: a part's address or options), else None."""
    refused = None


class SimControlError(OrfaError, RuntimeError):
    """The simulator refused a control request (its ``ERR ...`` text), or
    closed the control socket (orfa.simctl)."""


class FlashError(OrfaError):
    """Flashing cannot start: no avrdude, no firmware, an unreadable file (orfa.flash)."""


class ElfError(OrfaError, ValueError):
    """The file is not an AVR ELF this package can read (orfa.ihex)."""


class VcdError(OrfaError, ValueError):
    """A file that is not a VCD this package can read (the message says
    where; orfa.vcd)."""


class PlotUnavailable(OrfaError, RuntimeError):
    """matplotlib, the extra `orfa[plot]`, is not installed (orfa.plot)."""


class UsageError(OrfaError):
    """A mistake on the `orfa` command line found after parsing: exit status 2
    (orfa.cli)."""


class ControlError(OrfaError, ValueError):
    """A dashboard control request that is wrong in itself (a field missing
    or out of range): the page gets the message, the board is not asked
    (orfa.dash)."""


class NotFound(OrfaError, KeyError):
    """No board at that address on this dashboard, or no such control (orfa.dash)."""

    def __str__(self) -> str:
        return self.args[0]


class Refused(OrfaError):
    """The board did not do what a dashboard control asked (it refused, or a
    line belongs to another function; orfa.dash)."""


def explain(exc: BaseException) -> str:
    """One line for an error: a bare `ERROR xx` gets the code's meaning
    (from the board map, as the firmware's error enum gives it)."""
    text = str(exc) or type(exc).__name__
    code = getattr(exc, "code", None)
    if code is not None and text == "ERROR %02X" % code and code in _map.ERRORS:
        text += ": %s" % _map.ERRORS[code].text
    return text
