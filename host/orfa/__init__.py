"""ORFA host library: talk to an ORFA serial gateway (real or simulated)."""

from .protocol import (  # noqa: F401
    MAX_REPLY_CHARS, MAX_REQUEST_CHARS, AddressNackError, DataError,
    DataNackError, DriverRecord, ErrorCode, HexError, IncompleteError,
    InternalError, LimitError, OrfaError, ProtocolError, Read, ReadResult,
    ReplyTimeout, UnknownCommandError, Write, WriteResult,
)
from .errors import (  # noqa: F401
    BadLengthError, BadValueError, DroppedError, NoDriverError, NoRegisterError, NotBoundError,
    NotReadableError, NotWritableError, PinBusyError, RegisterError, SerialError,
    Status,
)
from .gateway import Gateway  # noqa: F401
from .board import Board  # noqa: F401
from .clients.servo import ServoRange  # noqa: F401

__version__ = "0.1.0"
