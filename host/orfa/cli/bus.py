"""The bus commands, in the manner of i2c-tools: version, scan (i2cdetect),
read (i2cget), write (i2cset), transfer (i2ctransfer), and request (raw
protocol lines)."""

from __future__ import annotations

import re
import sys
from typing import List, Sequence

from .. import protocol as p
from ..board import Board
from ..gateway import SCAN_FIRST, SCAN_LAST
from .common import (UsageError, address, arg, byte, command, connect, explain,
                     hex_bytes, number, show_address)
from .names import board_of

#: What scan probes by default: i2cdetect's range (0x00-0x07 and 0x78-0x7F
#: are reserved by the I2C specification).


# --- version ------------------------------------------------------------------

def cmd_version(args) -> int:
    """the gateway's protocol version and board

    Print the protocol version the gateway speaks (V) and its board (with
    --addr: the slave's), known from its drivers.

    example: orfa --sim m32d version
    """
    addr = None if args.addr is None else address(args, args.addr, "--addr")
    with connect(args) as gw:
        version = gw.version()
        board = Board(gw, addr)
        model = board_of(board)
        where = show_address(args, board.addr)
    print("protocol %s" % version)
    print("board    %s at %s" % (model, where) if addr is not None else "board    %s" % model)
    return 0


# --- scan ---------------------------------------------------------------------

def scan_grid(found: Sequence[int], first: int, last: int) -> str:
    """i2cdetect's grid of 7-bit addresses: the address where a device
    answered, `--` where none did, blanks outside first..last."""
    lines = ["     " + "  ".join("%x" % col for col in range(16))]
    for row in range(0, 0x80, 16):
        cells = []
        for a in range(row, row + 16):
            if not first <= a <= last:
                cells.append("  ")
            else:
                cells.append("%02x" % a if a in found else "--")
        lines.append(("%02x: " % row + " ".join(cells)).rstrip())
    return "\n".join(lines)


def cmd_scan(args) -> int:
    """probe every address, i2cdetect's grid

    Probe each 7-bit address with an empty write (S<addr> P, pipelined) and
    print i2cdetect's grid: the 7-bit address where a device answered, --
    where none did. The line under it lists the same devices in the form
    the other commands take (8-bit, or 7-bit with --7bit); 8-bit = 7-bit <<
    1, so the gateway's own 0xAA is 0x55 in the grid.

    example: orfa --sim m32d --eeprom 0xA0 scan
    """
    first, last = (0x00, 0x7F) if args.all else (SCAN_FIRST, SCAN_LAST)
    with connect(args) as gw:
        local = gw.local_address()
        found = gw.scan(first, last)
    print(scan_grid(found, first, last))
    own = " (%s: the gateway itself)" % show_address(args, local) \
        if local >> 1 in found else ""
    form = "7-bit" if args.seven_bit else "8-bit"
    print("%s: %s%s" % (form, " ".join(show_address(args, a << 1) for a in found) or "none",
                        own))
    return 0


# --- read, write --------------------------------------------------------------

#: The longest register read: `SW A SR <2n> P` within 127 characters.
MAX_READ = (p.MAX_REPLY_CHARS - len("SWASRP")) // 2


def cmd_read(args) -> int:
    """read registers (i2cget)

    Select register REG of device ADDR and read COUNT bytes (S ADDR REG S
    ADDR|1 COUNT P); print them as hex. {ADDRESS_RULE}

    example: orfa read 0xA0 0x10 2  ->  0x41 0x42
    """
    addr = address(args, args.addr_arg)
    if not 1 <= args.count <= MAX_READ:
        raise UsageError("COUNT is 1..%d (a reply holds %d characters)"
                         % (MAX_READ, p.MAX_REPLY_CHARS))
    frames = p.register_read_frames(addr, args.reg, args.count)
    _check_fits(frames)
    with connect(args) as gw:
        data = _transact(gw, frames, "%s register 0x%02X" % (show_address(args, addr), args.reg))
    print(hex_bytes(data[-1].data))
    return 0


def cmd_write(args) -> int:
    """write registers (i2cset)

    Write BYTEs to register REG of device ADDR (S ADDR REG BYTE... P). No
    BYTE: only select REG. {ADDRESS_RULE}

    example: orfa write 0xA0 0x10 0x41 0x42
    """
    addr = address(args, args.addr_arg)
    frames = p.register_write_frames(addr, args.reg, args.bytes)
    _check_fits(frames)
    with connect(args) as gw:
        _transact(gw, frames, "%s register 0x%02X" % (show_address(args, addr), args.reg))
    return 0


def _check_fits(frames) -> str:
    try:
        return p.format_transaction(frames)
    except (p.LimitError, ValueError) as exc:
        raise UsageError(str(exc)) from None


def _transact(gw, frames, what: str):
    try:
        return gw.transaction(frames)
    except p.OrfaError as exc:
        raise p.OrfaError("%s: %s" % (what, explain(exc)), code=exc.code) from None


# --- transfer -----------------------------------------------------------------

_MSG_RE = re.compile(r"([rw])([0-9]+|0x[0-9a-f]+)(?:@(.+))?\Z", re.IGNORECASE)


def parse_messages(args, words: Sequence[str]) -> List[p.Frame]:
    """i2ctransfer's messages: `{r|w}LENGTH[@ADDR]`, a write followed by its
    LENGTH data bytes; a message without @ADDR goes to the previous one's."""
    frames: List[p.Frame] = []
    addr = None
    i = 0
    while i < len(words):
        m = _MSG_RE.match(words[i])
        if m is None:
            raise UsageError("%r: a message is {r|w}LENGTH[@ADDR] (w2@0xA0, r1)" % words[i])
        kind, length = m.group(1).lower(), int(m.group(2), 0)
        if m.group(3) is not None:
            try:
                addr = address(args, int(m.group(3), 0))
            except ValueError:
                raise UsageError("%r: ADDR like 0xA0" % words[i]) from None
        elif addr is None:
            raise UsageError("%r: the first message needs @ADDR" % words[i])
        i += 1
        if kind == "r":
            if length < 1:
                raise UsageError("%r: a read reads 1 byte or more" % words[i - 1])
            frames.append(p.Read(addr, length))
            continue
        data = words[i:i + length]
        if len(data) < length or any(_MSG_RE.match(w) for w in data):
            raise UsageError("%r: %d data bytes must follow" % (words[i - 1], length))
        try:
            frames.append(p.Write(addr, bytes(byte(w) for w in data)))
        except Exception:
            raise UsageError("%r: data bytes are 0..0xFF: %s"
                             % (words[i - 1], " ".join(data))) from None
        i += length
    if not frames:
        raise UsageError("no message")
    return frames


def cmd_transfer(args) -> int:
    """several messages in one transaction (i2ctransfer)

    Messages as i2ctransfer takes them, sent as one request with a repeated
    START between them: {r|w}LENGTH[@ADDR], a write followed by its LENGTH
    data bytes; a message without @ADDR goes to the previous message's
    address. Each read prints a line of hex bytes. i2ctransfer's data
    suffixes (+, -, =, p) are not taken. {ADDRESS_RULE}

    example: orfa transfer w1@0xA0 0x10 r2  ->  0x41 0x42
    """
    frames = parse_messages(args, args.messages)
    _check_fits(frames)
    with connect(args) as gw:
        results = _transact(gw, frames, "transfer")
    for result in results:
        if isinstance(result, p.ReadResult):
            print(hex_bytes(result.data))
    return 0


# --- request ------------------------------------------------------------------

def cmd_request(args) -> int:
    """send protocol requests, print the replies

    Send each REQUEST line (docs/protocol.md) and print its reply. Exit
    status 1 when a reply is an ERROR (all replies are printed).

    example: orfa request --port /dev/ttyUSB0 V "S A0 10 S A1 02 P"
    """
    status = 0
    with connect(args) as gw:
        for line in args.requests:
            reply = gw.request(line)
            print(reply, flush=True)
            if reply.startswith("ERROR") and status == 0:
                try:
                    p.check_error(reply)
                except p.OrfaError as exc:
                    print("orfa: %s: %s" % (line, explain(exc)), file=sys.stderr)
                status = 1
    return status


# --- the parsers --------------------------------------------------------------

def add_parsers(sub, common) -> None:
    where = (arg("addr_arg", type=number, metavar="ADDR"),
             arg("reg", type=byte, metavar="REG"))
    command(sub, [common], cmd_version)
    command(sub, [common], cmd_scan,
            arg("-a", "--all", action="store_true",
                help="probe 0x00-0x7F (default 0x08-0x77, as i2cdetect)"))
    command(sub, [common], cmd_read, *where,
            arg("count", type=number, nargs="?", default=1, metavar="COUNT",
                help="bytes to read, 1..%d (default 1)" % MAX_READ))
    command(sub, [common], cmd_write, *where,
            arg("bytes", type=byte, nargs="*", metavar="BYTE"))
    command(sub, [common], cmd_transfer, arg("messages", nargs="+", metavar="MSG"))
    command(sub, [common], cmd_request, arg("requests", nargs="+", metavar="REQUEST"))
