"""ORFA serial gateway protocol V1.1: format requests, parse replies.

Pure: no I/O. Everything here is checked without a board (tests/host/).
The rules are those of docs/protocol.md; addresses are in the 8-bit form
used by the protocol (bit 0 is the R/W bit).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Iterable, List, Optional, Sequence, Union

from .boardmap import F_CPU  # noqa: F401 (the boards' clock, from board.h through the map)
# The protocol's errors live in orfa.errors with the rest of the tree; they
# are this module's names too (orfa.protocol.OrfaError, p.HexError).
from .errors import (  # noqa: F401
    ERRORS_BY_CODE, AddressNackError, DataError, DataNackError, ErrorCode, HexError,
    IncompleteError, InternalError, LimitError, OrfaError, ProtocolError, ReplyTimeout,
    UnknownCommandError, error_for_code,
)

PROTOCOL_VERSION = "1.1"

#: A request holds at most this many characters before its terminator.
MAX_REQUEST_CHARS = 128
#: A reply's text (without CR LF) holds at most this many characters.
MAX_REPLY_CHARS = 127

#: What the host sends after each request.
REQUEST_TERMINATOR = "\n"
#: What ends every reply line.
REPLY_TERMINATOR = "\r\n"

DEFAULT_LOCAL_ADDRESS = 0xAA
#: The clock asked for at reset (100 kHz; the TWI makes 99.632 kHz).
DEFAULT_CLOCK_KHZ = 0x64

#: The serial line's rates (docs/protocol.md, "The line"): a fixed-rate build
#: takes any of BAUD_RATES, BAUD=auto detects AUTOBAUD_RATES. The Makefile's
#: lists are the source (a host test keeps them equal).
AUTOBAUD_RATES = (2400, 4800, 9600, 14400, 19200, 28800, 38400, 57600, 76800, 115200, 230400, 460800)
BAUD_RATES = AUTOBAUD_RATES
DEFAULT_BAUD = 115200
#: With BAUD=auto the host opens the line with these eight CRs and then
#: stays quiet for at least AUTOBAUD_QUIET_S before it talks.
AUTOBAUD_PREAMBLE = b"\r" * 8
AUTOBAUD_QUIET_S = 0.020


def autobaud_wait_s(baudrate: int) -> float:
    """Seconds from writing the preamble until the host may talk: its eight
    frames on the wire (10 bits each) and the quiet after them."""
    return len(AUTOBAUD_PREAMBLE) * 10.0 / baudrate + AUTOBAUD_QUIET_S


# --- frames -----------------------------------------------------------------

def _check_byte(name: str, value: int) -> int:
    if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 0xFF:
        raise ValueError("%s must be an int 0..255, not %r" % (name, value))
    return value


@dataclass(frozen=True)
class Write:
    """A write frame: `S<addr+w><data...>`; bit 0 of addr is ignored."""

    addr: int
    data: bytes = b""

    def __post_init__(self):
        _check_byte("address", self.addr)
        object.__setattr__(self, "data", bytes(self.data))

    @property
    def address_byte(self) -> int:
        return self.addr & 0xFE

    def reply_chars(self) -> int:
        return 2 + len(self.data)                  # "SW" + one "A" per byte


@dataclass(frozen=True)
class Read:
    """A read frame: `S<addr+r><count>`; bit 0 of addr is ignored."""

    addr: int
    count: int

    def __post_init__(self):
        _check_byte("address", self.addr)
        _check_byte("count", self.count)
        if self.count == 0:
            raise ValueError("a read frame reads at least 1 byte")

    @property
    def address_byte(self) -> int:
        return self.addr | 0x01

    def reply_chars(self) -> int:
        return 2 + 2 * self.count                  # "SR" + two digits per byte


Frame = Union[Write, Read]


@dataclass(frozen=True)
class WriteResult:
    """What a write frame answered: the number of acknowledged bytes."""

    acks: int


@dataclass(frozen=True)
class ReadResult:
    """What a read frame answered: the bytes read."""

    data: bytes


FrameResult = Union[WriteResult, ReadResult]


# --- requests ---------------------------------------------------------------

def check_request(line: str) -> str:
    """Return line if the gateway can take it as one request, else raise."""
    if not isinstance(line, str):
        raise TypeError("a request is a str, not %r" % type(line).__name__)
    if "\r" in line or "\n" in line:
        raise ValueError("a request is one line: no CR or LF inside")
    try:
        line.encode("ascii")
    except UnicodeEncodeError:
        raise ValueError("a request is ASCII text") from None
    if len(line) > MAX_REQUEST_CHARS:
        raise LimitError("request of %d characters, the limit is %d"
                         % (len(line), MAX_REQUEST_CHARS))
    return line


def encode_request(line: str) -> bytes:
    """The bytes to send for one request, terminator included."""
    return (check_request(line) + REQUEST_TERMINATOR).encode("ascii")


def format_version() -> str:
    return "V"


def format_clear() -> str:
    return "X"


def format_local_address(new: Optional[int] = None) -> str:
    if new is None:
        return "L"
    _check_byte("local address", new)
    if new & 0xFE == 0:
        raise ValueError("local address 0x%02X is not allowed" % new)
    return "L%02X" % new


def format_clock(khz: Optional[int] = None) -> str:
    if khz is None:
        return "C"
    if not isinstance(khz, int) or not 1 <= khz <= 0xFFFF:
        raise ValueError("clock must be 1..65535 kHz, not %r" % (khz,))
    return "C%04X" % khz


def reply_length(frames: Sequence[Frame]) -> int:
    """Characters of the reply text a transaction gets (without CR LF)."""
    return sum(f.reply_chars() for f in frames) + 1      # final "P"


def format_transaction(frames: Sequence[Frame]) -> str:
    """`S..S..P` for a list of Write/Read frames, checked against the limits."""
    frames = list(frames)
    if not frames:
        raise ValueError("a transaction has at least one frame")
    parts = []
    for frame in frames:
        if isinstance(frame, Write):
            parts.append("S%02X%s" % (frame.address_byte, frame.data.hex().upper()))
        elif isinstance(frame, Read):
            parts.append("S%02X%02X" % (frame.address_byte, frame.count))
        else:
            raise TypeError("not a frame: %r" % (frame,))
    line = "".join(parts) + "P"
    check_request(line)
    n = reply_length(frames)
    if n > MAX_REPLY_CHARS:
        raise LimitError("reply of %d characters, the limit is %d" % (n, MAX_REPLY_CHARS))
    return line


# --- replies ----------------------------------------------------------------

_ERROR_RE = re.compile(r"ERROR ([0-9A-F]{2})\Z")


def strip_reply(reply: Union[str, bytes]) -> str:
    """Reply text without its CR LF; bytes are decoded as ASCII."""
    if isinstance(reply, (bytes, bytearray)):
        try:
            reply = bytes(reply).decode("ascii")
        except UnicodeDecodeError:
            raise ProtocolError("reply is not ASCII: %r" % (reply,)) from None
    if reply.endswith(REPLY_TERMINATOR):
        reply = reply[:-len(REPLY_TERMINATOR)]
    return reply


def check_error(reply: Union[str, bytes]) -> str:
    """Raise the OrfaError of an `ERROR xx` reply; return any other reply text."""
    text = strip_reply(reply)
    if text.startswith("ERROR"):
        m = _ERROR_RE.match(text)
        if m is None:
            raise ProtocolError("malformed error reply %r" % text)
        raise error_for_code(int(m.group(1), 16))
    if len(text) > MAX_REPLY_CHARS:
        raise ProtocolError("reply of %d characters is over the limit" % len(text))
    return text


def _parse(reply: Union[str, bytes], pattern: str, what: str) -> "re.Match[str]":
    """The match of a reply to one of V, X, L, C (or the error it is)."""
    text = check_error(reply)
    m = re.match(pattern + r"\Z", text)
    if m is None:
        raise ProtocolError("not a %s reply: %r" % (what, text))
    return m


def parse_version(reply: Union[str, bytes]) -> str:
    return _parse(reply, r"V(\d+\.\d+)", "version").group(1)


def parse_clear(reply: Union[str, bytes]) -> None:
    _parse(reply, "X", "clear")


def parse_local_address(reply: Union[str, bytes]) -> int:
    return int(_parse(reply, "L([0-9A-F]{2})", "local address").group(1), 16)


def parse_clock(reply: Union[str, bytes]) -> int:
    return int(_parse(reply, "C([0-9A-F]{4})", "clock").group(1), 16)


_FRAME_RE = re.compile(r"SW(A*)|SR((?:[0-9A-F]{2})+)")


def parse_transaction(reply: Union[str, bytes],
                      frames: Optional[Sequence[Frame]] = None) -> List[FrameResult]:
    """Results of an I2C request's reply, one per frame, in order.

    With frames given, the reply must match them (kind, ack count, byte count).
    """
    text = check_error(reply)
    if not text.endswith("P") or not text.startswith("S"):
        raise ProtocolError("not a transaction reply: %r" % text)
    results: List[FrameResult] = []
    pos = 0
    body = text[:-1]
    while pos < len(body):
        m = _FRAME_RE.match(body, pos)
        if m is None:
            raise ProtocolError("not a transaction reply: %r (at %d)" % (text, pos))
        if m.group(0).startswith("SW"):
            results.append(WriteResult(len(m.group(1))))
        else:
            results.append(ReadResult(bytes.fromhex(m.group(2))))
        pos = m.end()
    if frames is not None:
        _match_frames(text, results, list(frames))
    return results


def _match_frames(text: str, results: List[FrameResult], frames: List[Frame]) -> None:
    if len(results) != len(frames):
        raise ProtocolError("%d frames sent, %d answered: %r" % (len(frames), len(results), text))
    for frame, result in zip(frames, results):
        if isinstance(frame, Write):
            ok = isinstance(result, WriteResult) and result.acks == len(frame.data)
        else:
            ok = isinstance(result, ReadResult) and len(result.data) == frame.count
        if not ok:
            raise ProtocolError("reply %r does not match frame %r" % (text, frame))


# --- register semantics (docs/registers.md) ---------------------------------

def register_write_frames(addr: int, reg: int, data: Iterable[int] = b"") -> List[Frame]:
    """Frames that write data to register reg (no data: select reg)."""
    return [Write(addr, bytes([_check_byte("register", reg)]) + bytes(data))]


def register_read_frames(addr: int, reg: int, count: int) -> List[Frame]:
    """Frames that select register reg and read count bytes from it."""
    return register_write_frames(addr, reg) + [Read(addr, count)]


@dataclass(frozen=True)
class DriverRecord:
    """One introspection record: `[UID hi][UID lo][major][minor][start][count]`."""

    uid: int
    major: int
    minor: int
    start: int
    count: int

    RECORD_SIZE = 6

    @classmethod
    def parse(cls, data: bytes) -> "DriverRecord":
        if len(data) != cls.RECORD_SIZE:
            raise ProtocolError("an introspection record has 6 bytes, not %d" % len(data))
        return cls((data[0] << 8) | data[1], data[2], data[3], data[4], data[5])

    @classmethod
    def parse_many(cls, data: bytes) -> List["DriverRecord"]:
        if len(data) % cls.RECORD_SIZE:
            raise ProtocolError("%d bytes are not whole records" % len(data))
        return [cls.parse(data[i:i + 6]) for i in range(0, len(data), 6)]


# --- the TWI clock (docs/protocol.md) ---------------------------------------

def twi_clock(khz: int, f_cpu: int = F_CPU):
    """(kHz reply, Hz made, TWBR, TWPS) the gateway sets for `C<khz>`.

    The fastest rate F_CPU / (16 + 2*TWBR*4^TWPS) not above khz, found with
    the smallest prescaler that reaches it; the reply is that rate in kHz,
    rounded down.
    """
    if not 1 <= khz <= 0xFFFF:
        raise ValueError("clock must be 1..65535 kHz")
    for twps in range(4):
        step = 2 * 4 ** twps
        # smallest divisor d = 16 + step*twbr with f_cpu / d <= khz*1000
        need = -(-f_cpu // (khz * 1000))                 # ceil(f_cpu / hz)
        twbr = max(0, -(-(need - 16) // step))
        if twbr <= 255:
            div = 16 + step * twbr
            return f_cpu // (div * 1000), f_cpu / div, twbr, twps
    raise ValueError("%d kHz is below the slowest rate" % khz)
