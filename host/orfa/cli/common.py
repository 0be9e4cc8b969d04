"""What every `orfa` command shares: numbers and addresses from the command
line, the board connection (a port or a simulated board), error messages."""

from __future__ import annotations

import argparse
import contextlib
import inspect
import math
import os
from typing import Iterator, List, Optional

from .. import boardmap
from .. import protocol as p
from ..errors import UsageError, explain  # noqa: F401 (the commands' errors, one line each)
from ..gateway import Gateway, os_reason
from ..locate import gateway_firmware
from ..sim import BOARDS, SimBoard, SimError, part_kinds

#: The environment variable that gives --port its default.
PORT_ENV = "ORFA_PORT"

#: What the help of every command says about addresses.
ADDRESS_RULE = ("Addresses are the protocol's 8-bit form (0xA0, 0x10, the gateway's"
                " own 0xAA: even, bit 0 is the R/W bit), as in requests and everywhere"
                " else in ORFA; with --7bit they are i2c-tools' 7-bit form (0x50, 0x08,"
                " 0x55), 8-bit = 7-bit << 1.")


def number(text: str) -> int:
    """An integer as C writes it: 16, 0x10, 0o20, 0b10000."""
    try:
        return int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError("%r is not a number (16, 0x10)" % text) from None


def byte(text: str) -> int:
    value = number(text)
    if not 0 <= value <= 0xFF:
        raise argparse.ArgumentTypeError("%s is not a byte (0..0xFF)" % text)
    return value


#: The serial rates --baud takes: Linux's named rates go up to 4000000; the
#: gateway runs protocol.BAUD_RATES (2400..460800).
MIN_BAUD, MAX_BAUD = 50, 4000000
#: The longest --timeout (and adc --watch interval): a reply comes within milliseconds or not at all,
#: and an hour is far beyond any board's.
MAX_TIMEOUT_S = 3600.0


def baud_rate(text: str) -> int:
    """--baud: a serial rate, MIN_BAUD..MAX_BAUD (0 or 10**20 are no rate)."""
    try:
        value = int(text, 10)
    except ValueError:
        value = None
    if value is None or not MIN_BAUD <= value <= MAX_BAUD:
        raise argparse.ArgumentTypeError(
            "%r is not a serial rate: %d..%d baud (the gateway's default is %d)"
            % (text, MIN_BAUD, MAX_BAUD, p.DEFAULT_BAUD))
    return value


def _finite(text: str) -> Optional[float]:
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def seconds(text: str) -> float:
    """--timeout: seconds, above 0 and at most MAX_TIMEOUT_S (not nan, not
    inf: they would hang or overflow the OS's wait)."""
    value = _finite(text)
    if value is None or not 0 < value <= MAX_TIMEOUT_S:
        raise argparse.ArgumentTypeError(
            "%r: seconds above 0, at most %g (0.5, 2)" % (text, MAX_TIMEOUT_S))
    return value


def interval(text: str) -> float:
    """adc --watch: seconds between reads, 0 (as fast as the line goes) up
    to MAX_TIMEOUT_S."""
    value = _finite(text)
    if value is None or not 0 <= value <= MAX_TIMEOUT_S:
        raise argparse.ArgumentTypeError(
            "%r: seconds, 0 to %g (0.5)" % (text, MAX_TIMEOUT_S))
    return value


def volts(text: str) -> float:
    """--vref: a voltage above 0 (not nan, not inf)."""
    value = _finite(text)
    if value is None or value <= 0:
        raise argparse.ArgumentTypeError("%r is not a reference voltage: volts above 0"
                                         " (5, 2.56)" % text)
    return value


def address(args, value: int, what: str = "address") -> int:
    """A command-line address as the protocol's 8-bit form (see ADDRESS_RULE)."""
    if getattr(args, "seven_bit", False):
        if not 0 <= value <= 0x7F:
            raise UsageError("%s 0x%02X: a 7-bit address is 0x00..0x7F" % (what, value))
        return value << 1
    if not 0 <= value <= 0xFF:
        raise UsageError("%s %s: out of range: an 8-bit address is 0x00..0xFE"
                         % (what, "0x%02X" % value if value >= 0 else value))
    if value & 1:
        hint = " (the 7-bit 0x%02X is 0x%02X, or give --7bit)" % (value, value << 1) \
            if 0 <= value <= 0x7F else ""
        raise UsageError("%s 0x%02X: an 8-bit address is even, 0x00..0xFE%s"
                         % (what, value, hint))
    return value


def show_address(args, addr8: int) -> str:
    """An 8-bit address in the form the command line uses."""
    if getattr(args, "seven_bit", False):
        return "0x%02X" % (addr8 >> 1)
    return "0x%02X" % addr8


def open_gateway(url: str, args) -> Gateway:
    """A Gateway on url; a port that cannot be opened is a UsageError."""
    try:
        return Gateway(url, baudrate=args.baud, timeout=args.timeout,
                       autobaud=args.autobaud)
    except (ValueError, p.OrfaError) as exc:         # SerialError, a bad rate
        raise UsageError("cannot open %s: %s" % (url, os_reason(exc, errno=False))) from None


def slave_spec(text: str):
    """`BOARD:ADDR[:ELF]` -> (board, addr, elf or None: the board's slave build)."""
    parts = text.split(":", 2)
    if len(parts) < 2 or parts[0] not in BOARDS:
        raise argparse.ArgumentTypeError(
            "%r: BOARD:ADDR[:ELF] with BOARD one of %s" % (text, ", ".join(BOARDS)))
    try:
        addr = int(parts[1], 0)
    except ValueError:
        raise argparse.ArgumentTypeError("%r: ADDR like 0x10" % text) from None
    _check_device_address(text, addr)
    return (parts[0], addr, parts[2] if len(parts) == 3 and parts[2] else None)


def eeprom_spec(text: str) -> int:
    """`ADDR` of --eeprom, checked as --slave's is."""
    try:
        addr = int(text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError("%r: ADDR like 0xA0" % text) from None
    _check_device_address(text, addr)
    return addr


def part_spec(text: str):
    """`KIND@ADDR[:OPTIONS]` of --part -> (kind, addr, options); ADDR checked
    as --eeprom's, KIND against the simulator's kinds."""
    kind, at, rest = text.partition("@")
    addr_text, _, opts = rest.partition(":")
    kinds = part_kinds()
    if not at or not kind:
        raise argparse.ArgumentTypeError("%r: KIND@ADDR[:OPTIONS] like bmp280@0xEC" % text)
    if kinds and kind not in kinds:
        raise argparse.ArgumentTypeError("%r: no part %r (the simulator's: %s)"
                                         % (text, kind, ", ".join(kinds)))
    try:
        addr = int(addr_text, 0)
    except ValueError:
        raise argparse.ArgumentTypeError("%r: ADDR like 0xEC" % text) from None
    _check_device_address(text, addr)
    return (kind, addr, opts)


def _check_device_address(text: str, addr: int) -> None:
    """A simulated device's 8-bit bus address: even, outside the addresses
    I2C reserves, and not the gateway's own (its requests never reach the bus)."""
    if not boardmap.address_ok(addr):
        raise argparse.ArgumentTypeError("%r: ADDR must be %s" % (text, boardmap.ADDRESS_TEXT))
    if addr == p.DEFAULT_LOCAL_ADDRESS:
        raise argparse.ArgumentTypeError("%r: 0x%02X is the gateway's own address (its"
                                         " requests never reach the bus)" % (text, addr))


def adc_spec(text: str):
    """`CH=MV` -> (channel, millivolts)."""
    ch, sep, mv = text.partition("=")
    try:
        pair = (int(ch, 0), int(mv, 0))
    except ValueError:
        pair = None
    if not sep or pair is None or not 0 <= pair[0] <= 7 or pair[1] < 0:
        raise argparse.ArgumentTypeError("%r: CH=MV with CH 0-7 (3=1200)" % text)
    return pair


def add_sim_devices(parser, suppress: bool = False) -> None:
    """The simulated board's devices: for `sim`, and for --sim."""
    default = argparse.SUPPRESS if suppress else None
    parser.add_argument("--eeprom", type=eeprom_spec, action="append", default=default or [],
                        metavar="ADDR",
                        help="a 24C02-like EEPROM at the 8-bit bus address ADDR (0xA0;"
                             " %s, not the gateway's 0xAA), repeatable"
                             % boardmap.ADDRESS_TEXT)
    parser.add_argument("--part", type=part_spec, action="append", default=default or [],
                        metavar="KIND@ADDR[:OPTIONS]",
                        help="a part of KIND on the I2C bus at the 8-bit ADDR, checked as"
                             " --eeprom's (bmp280@0xEC, 24lc32@0xA8:wp; `orfa-sim --help`"
                             " lists the kinds), repeatable")
    parser.add_argument("--slave", type=slave_spec, action="append", default=default or [],
                        metavar="BOARD:ADDR[:ELF]",
                        help="a slave board on the bus at the 8-bit ADDR (%s,"
                             " not the gateway's 0xAA; repeatable); ELF"
                             " defaults to build/robot/<board>-<ADDR>/orfa.elf (make robot)"
                             " if built, else build/<board>-slave/orfa.elf"
                             % boardmap.ADDRESS_TEXT)
    parser.add_argument("--adc", type=adc_spec, action="append", default=default or [],
                        metavar="CH=MV", help="analog input CH (0-7) at MV millivolts,"
                                              " repeatable")
    parser.add_argument("--spi", action="append", default=default or [],
                        metavar="[SLAVE/]KIND@PIN[:mode=N][:lsb]",
                        help="an SPI device: eeprom25 or mcp3008 selected by PIN"
                             " (eeprom25@C2), repeatable")


def sim_board(board: str, args, **kw) -> SimBoard:
    """A SimBoard with the devices of args (not started), running the
    gateway for --baud and --autobaud (sim_firmware) unless
    firmware= names one; two devices at one address are a UsageError."""
    if kw.get("firmware") is None:
        kw["firmware"] = sim_firmware(board, args)
    seen = {}
    parts = getattr(args, "part", None) or ()
    for opt, addr in ([("--eeprom", a) for a in getattr(args, "eeprom", None) or ()]
                      + [("--part", q[1]) for q in parts]
                      + [("--slave", s[1]) for s in getattr(args, "slave", None) or ()]):
        if addr in seen:
            raise UsageError("%s 0x%02X: %s put a device there already"
                             % (opt, addr, seen[addr]))
        seen[addr] = opt
    return SimBoard(board, eeproms=getattr(args, "eeprom", None) or (),
                    slaves=getattr(args, "slave", None) or (), parts=parts,
                    adc=dict(getattr(args, "adc", None) or ()),
                    spi=getattr(args, "spi", None) or (), **kw)


def sim_firmware(board: str, args):
    """The gateway a simulated board runs for --baud and --autobaud: the
    BAUD=auto build with --autobaud (it finds --baud from the preamble),
    else the one built for --baud (orfa.locate.gateway_firmware). A rate
    autobaud does not find is a ValueError saying so."""
    if not args.autobaud:
        return gateway_firmware(board, args.baud)
    if args.baud not in p.AUTOBAUD_RATES:
        raise ValueError("no %s gateway finds %d baud: BAUD=auto detects %s"
                         % (board, args.baud, " ".join(map(str, p.AUTOBAUD_RATES))))
    return gateway_firmware(board, "auto")


@contextlib.contextmanager
def connect(args) -> Iterator[Gateway]:
    """The Gateway of --port URL (or $ORFA_PORT), or of a board --sim starts
    for this one command (stopped when the command ends), its gateway built
    for --baud (sim_board: with --autobaud, the BAUD=auto one). An explicit --sim
    wins over $ORFA_PORT; --port and --sim both given is a usage error."""
    devices = [opt for opt in ("eeprom", "part", "slave", "adc", "spi")
               if getattr(args, opt, None)]
    if args.sim is None and devices:
        raise UsageError("--%s describes a simulated board: give --sim BOARD too" % devices[0])
    if args.sim is not None:
        if args.port:
            raise UsageError("give --port or --sim, not both")
        try:
            sim = sim_board(args.sim, args, trace=False, control=args.autobaud).start()
        except (SimError, ValueError) as exc:
            raise UsageError(getattr(exc, "refused", None) or str(exc)) from None
        try:
            # the preamble's quiet passes in simulated time, not on the wall clock
            with sim.gateway(args.baud, autobaud=args.autobaud, timeout=args.timeout) as gw:
                yield gw
        finally:
            sim.stop()
        return
    url = args.port or env_port()        # $ORFA_PORT only where no --sim is given
    if not url:
        raise UsageError("no board: give --port URL (or set %s) or --sim BOARD (%s)"
                         % (PORT_ENV, "|".join(BOARDS)))
    with open_gateway(url, args) as gw:
        yield gw


def arg(*names, **options):
    """One argument of command(): arg("--all", action="store_true", help=...)."""
    return names, options


def command(sub, parents, func, *arguments, **fill) -> argparse.ArgumentParser:
    """Add the command `func` runs, named after it (cmd_scan: `scan`), to the
    subparsers `sub`, with `arguments` (arg(...)), and return its parser.
    The function's docstring says the rest: its first line is the help, its
    last paragraph the epilog (the examples), the paragraphs between them
    the description, where `{NAME}` stands for fill[NAME] ({ADDRESS_RULE}:
    ADDRESS_RULE)."""
    paragraphs = inspect.cleandoc(func.__doc__).split("\n\n")
    description = " ".join(paragraphs[1:-1])
    for name, text in dict(fill, ADDRESS_RULE=ADDRESS_RULE).items():
        description = description.replace("{%s}" % name, str(text))
    cmd = sub.add_parser(func.__name__[len("cmd_"):], parents=list(parents),
                         help=paragraphs[0], description=description, epilog=paragraphs[-1])
    for names, options in arguments:
        cmd.add_argument(*names, **options)
    cmd.set_defaults(func=func)
    return cmd


def hex_bytes(data: bytes) -> str:
    """Bytes as i2cget prints them: 0x41 0x42."""
    return " ".join("0x%02x" % b for b in data)


def table(rows: List[List[str]], header: Optional[List[str]] = None) -> str:
    """Left-aligned columns, two spaces apart."""
    rows = ([header] if header else []) + rows
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip()
                     for row in rows)


def env_port() -> Optional[str]:
    return os.environ.get(PORT_ENV) or None
