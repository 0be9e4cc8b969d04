"""The driver commands: drivers, servo, motor, adc, gpio, spi, status; each
on the gateway itself or, with --addr, on a slave board (orfa.Board)."""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from typing import Iterator, List, Optional

from .. import boardmap
from .. import protocol as p
from ..board import Board
from ..clients.adc import CHANNELS as ADC_CHANNELS, VREF
from ..clients.motor import DUTY_RANGE, is_duty
from ..clients.servo import ServoRange
from .common import (UsageError, address, arg, byte, command, connect, explain, hex_bytes,
                     number, interval, show_address, table, volts)
from .names import board_of, driver_name


@contextlib.contextmanager
def open_board(args) -> Iterator[Board]:
    """The Board of --addr (None: the gateway itself) on the command's connection."""
    addr = None if args.addr is None else address(args, args.addr, "--addr")
    with connect(args) as gw:
        board = Board(gw, addr)
        try:
            yield board
        except p.OrfaError as exc:
            if exc.code is None or str(exc) != "ERROR %02X" % exc.code:
                raise
            # a bare ERROR reply: say whom it came from
            raise p.OrfaError("%s: %s" % (_where(args, board), explain(exc)),
                              code=exc.code) from None


def _where(args, board: Board) -> str:
    return show_address(args, board.addr)


# --- drivers ------------------------------------------------------------------

def registers(record) -> str:
    first, last = record.start, record.start + record.count - 1
    return "0x%02X" % first if record.count == 1 else "0x%02X-0x%02X" % (first, last)


def cmd_drivers(args) -> int:
    """the drivers a board reports (introspection)

    List the drivers of the gateway (or of the slave at --addr): UID, name,
    version and the registers each one maps.

    example: orfa --sim m32d drivers; orfa --port PORT drivers --addr 0x10
    """
    with open_board(args) as board:
        records = board.drivers
        where = _where(args, board)
        names = [driver_name(board, r.uid) for r in records]
        model = board_of(board)
    rows = [["%04X" % r.uid, name, "%d.%d" % (r.major, r.minor), registers(r)]
            for r, name in zip(records, names)]
    print("%s: %s, %d drivers" % (where, model, len(records)))
    print(table(rows, ["UID", "driver", "version", "registers"]))
    return 0


# --- servo ----------------------------------------------------------------------

#: The widths the servo driver makes (others it clamps to these).
SERVO_MIN_US = boardmap.load(boardmap.BOARDS[0]).limits["servo_min_us"]
SERVO_MAX_US = boardmap.load(boardmap.BOARDS[0]).limits["servo_max_us"]


def servo_range(text: str):
    """`MIN_US:MAX_US:MIN_DEG:MAX_DEG` -> ServoRange."""
    parts = text.split(":")
    try:
        if len(parts) != 4:
            raise ValueError
        return ServoRange(int(parts[0], 0), int(parts[1], 0), float(parts[2]), float(parts[3]))
    except (ValueError, TypeError):
        raise argparse.ArgumentTypeError(
            "%r: MIN_US:MAX_US:MIN_DEG:MAX_DEG like 1000:2000:-75:75" % text) from None


def _width(text: str) -> int:
    if text == "off":
        return 0
    us = number(text)
    if us != 0 and not SERVO_MIN_US <= us <= SERVO_MAX_US:
        raise argparse.ArgumentTypeError(
            "%s us: a width is %d..%d us (0 or off: no pulses)"
            % (text, SERVO_MIN_US, SERVO_MAX_US))
    return us


def _show_width(us: int) -> str:
    return "off" if us == 0 else "%d" % us


def cmd_servo(args) -> int:
    """servo pulse widths and angles

    servo: every channel's width; servo CH: its width in us (off: no
    pulses); servo CH US: set it (500..2500; 0 or off stops the pulses);
    servo CH --angle [DEG]: the angle, or set it, by the manual's formula
    deg = MIN_DEG + (MAX_DEG - MIN_DEG) * (us - MIN_US) / (MAX_US - MIN_US)
    over --range (default 1000:2000:-75:75); servo off: every channel off.

    example: orfa servo 3 1500; orfa servo 3 --angle 30; orfa servo 3 off
    """
    kw = {} if args.range is None else {"range": args.range}
    with open_board(args) as board:
        servo = board.servo
        if args.channel == "off":
            if args.us is not None or args.angle is not None:
                raise UsageError("servo off takes no width or angle")
            servo.off()
            return 0
        ch = _channel(args.channel, servo.channels)
        if ch is None:
            rows = [[str(c), _show_width(us)] for c, us in enumerate(servo.widths())]
            print(table(rows, ["channel", "us"]))
            return 0
        if args.us is not None and args.angle is not None:
            raise UsageError("give a width or --angle, not both")
        if args.us is not None:
            servo.set_width(ch, _width_checked(args.us))
        elif args.angle is not None and args.angle is not READ:
            servo.set_angle(ch, args.angle, **kw)
        elif args.angle is READ:
            us = servo.width(ch)                  # one read: the width is the angle
            print("off" if us == 0 else "%.1f" % kw.get("range", ServoRange()).degrees(us))
        else:
            print(_show_width(servo.width(ch)))
    return 0


def _width_checked(text: str) -> int:
    try:
        return _width(text)
    except argparse.ArgumentTypeError as exc:
        raise UsageError(str(exc)) from None


def _channel(text: Optional[str], channels: int) -> Optional[int]:
    if text is None:
        return None
    try:
        ch = int(text, 0)
    except ValueError:
        raise UsageError("channel %r: a number 0..%d (or off)" % (text, channels - 1)) from None
    if not 0 <= ch < channels:
        raise UsageError("channel %d: this board's channels are 0..%d" % (ch, channels - 1))
    return ch


class _Read:
    def __repr__(self) -> str:
        return "READ"


#: --angle without a value: print the angle.
READ = _Read()


def _angle(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("%r is not an angle in degrees" % text) from None


# --- motor ----------------------------------------------------------------------

def cmd_motor(args) -> int:
    """motor duty and direction

    motor: both motors' duty; motor N: motor N's (1 or 2); motor N DUTY:
    set it, {DUTY_RANGE} (the sign is the direction, 0 or stop stops it);
    motor stop: both stop.

    example: orfa motor 1 -128; orfa motor stop
    """
    with open_board(args) as board:
        motor = board.motor
        if args.n == "stop":
            if args.duty is not None:
                raise UsageError("motor stop takes no duty")
            motor.stop()
            return 0
        if args.n is None:
            rows = [[str(n), str(duty)] for n, duty in enumerate(motor.duties(), 1)]
            print(table(rows, ["motor", "duty"]))
            return 0
        n = _motor(args.n, motor.count)
        if args.duty is None:
            print(motor.get(n))
            return 0
        duty = 0 if args.duty == "stop" else _duty(args.duty)
        motor.set(n, duty)
    return 0


def _motor(text: str, count: int) -> int:
    try:
        n = int(text, 0)
    except ValueError:
        n = 0
    if not 1 <= n <= count:
        raise UsageError("motor %r: 1..%d (or stop)" % (text, count))
    return n


def _duty(text: str) -> int:
    try:
        duty = int(text, 0)
    except ValueError:
        duty = None
    if not is_duty(duty):
        raise UsageError("duty %r: %s (sign = direction, 0 or stop: stop)" % (text, DUTY_RANGE))
    return duty


# --- adc --------------------------------------------------------------------------

#: docs/registers.md, "ADC": an enabled channel's value is valid within 10 ms
#: of its configuration.
ADC_SETTLE_S = 0.010


def channel_list(text: str) -> List[int]:
    """`0-3,6` -> [0, 1, 2, 3, 6]; `all` -> 0..7; `none` -> []."""
    if text == "all":
        return list(range(ADC_CHANNELS))
    if text == "none":
        return []
    out: List[int] = []
    try:
        for part in text.split(","):
            first, _, last = part.partition("-")
            out += range(int(first, 0), int(last or first, 0) + 1)
    except ValueError:
        out = [-1]
    if not out or any(not 0 <= ch < ADC_CHANNELS for ch in out):
        raise argparse.ArgumentTypeError("%r: channels 0-7 like 0-3,6 (or all, none)" % text)
    return sorted(set(out))


def adc_table(reference: str, bits: int, channels, raw, vref: Optional[float]) -> str:
    head = "reference %s%s, %d bits" % (
        reference, "" if vref is None else " %.3f V" % vref, bits)
    rows = []
    for ch, value in enumerate(raw):
        if ch not in channels:
            rows.append([str(ch), "off", ""])
        else:
            volts = "" if vref is None else "%.3f" % (value * vref / (1 << bits))
            rows.append([str(ch), str(value), volts])
    return head + "\n" + table(rows, ["ch", "raw", "volts"])


def _settle(board: Board, args) -> None:
    """Let the conversions after a new configuration become valid: reads
    whose wire time adds up to ADC_SETTLE_S at the line's rate, so the time
    passes on the board's clock, simulated or real."""
    per_read = (len("SAA0DSAB10P\n") + len("SWASR") + 32 + len("P\r\n")) * 10.0 / args.baud
    for _ in range(int(ADC_SETTLE_S / per_read) + 2):
        board.adc.read()


def cmd_adc(args) -> int:
    """analog inputs: a table, or a live one

    Print the ADC's channels: raw value and volts (from the reference: AVCC
    5 V, internal 2.56 V; AREF needs --vref). --channels, --ref or --bits
    configure the ADC first (the board keeps it): the channels given
    (default all), the reference (default avcc), the resolution (default
    10). --watch redraws the table every SECONDS (in place on a terminal)
    until Ctrl-C (exit 0) or --count tables.

    example: orfa adc --channels 0-3 --ref avcc --watch 0.2
    """
    with open_board(args) as board:
        adc = board.adc
        if args.channels is not None or args.ref is not None or args.bits is not None:
            adc.configure(channels=range(ADC_CHANNELS) if args.channels is None
                          else args.channels,
                          reference=args.ref or "avcc", bits=args.bits or 10)
            _settle(board, args)
        reference, bits, channels = adc.config()
        vref = args.vref if args.vref is not None else VREF.get(reference)
        watching = args.watch is not None
        tty = watching and sys.stdout.isatty()
        shown = 0
        try:
            while True:
                text = adc_table(reference, bits, channels, adc.read(), vref)
                if tty and shown:
                    sys.stdout.write("\x1b[%dA\x1b[J" % (text.count("\n") + 1))
                elif shown:
                    sys.stdout.write("\n")
                sys.stdout.write(text + "\n")
                sys.stdout.flush()
                shown += 1
                if not watching or (args.count is not None and shown >= args.count):
                    break
                time.sleep(args.watch)
        except KeyboardInterrupt:
            pass
        if not channels and not watching:
            print("orfa: no ADC channel is on: --channels 0-7 turns them on", file=sys.stderr)
    return 0


# --- gpio -----------------------------------------------------------------------

def _port(board: Board, text: str) -> str:
    ports = board.gpio.ports
    if len(text) != 1 or text.upper() not in ports:
        raise UsageError("port %r: this board's GPIO ports are %s" % (text, ", ".join(ports)))
    return text.upper()


def cmd_gpio(args) -> int:
    """GPIO levels and modes

    gpio: every port's levels (PINx) and modes (DDRx, 1 = output); gpio
    PORT: that port's; gpio PORT VALUE [MASK]: set the lines in MASK
    (default all): an output's level, an input's pull-up; --output/--input
    MASK make those lines outputs or inputs first. Lines another function
    holds are left as they are.

    example: orfa gpio B 0x05 --output 0x0F
    """
    with open_board(args) as board:
        gpio = board.gpio
        if args.gpio_port is None:
            ports = gpio.ports
        else:
            ports = _port(board, args.gpio_port)
            if args.output is not None:
                gpio.set_modes(ports, 0xFF, args.output)
            if args.input is not None:
                gpio.set_modes(ports, 0x00, args.input)
            if args.value is not None:
                gpio.write(ports, args.value, 0xFF if args.mask is None else args.mask)
            if args.output is not None or args.input is not None or args.value is not None:
                return 0
        rows = []
        for port in ports:
            levels, modes = gpio.read(port), gpio.modes(port)
            rows.append([port, "0x%02X" % levels, "{:08b}".format(levels),
                         "0x%02X" % modes, "{:08b}".format(modes)])
    print(table(rows, ["port", "levels", "(7..0)", "modes", "(1 = output)"]))
    return 0


# --- spi --------------------------------------------------------------------------

def cmd_spi(args) -> int:
    """SPI chip selects, bus settings, transfers

    spi bind CH PORT LINE: GPIO line PORT LINE is channel CH's chip select;
    spi config: print the bus settings and chip selects, or set them
    (--div, --mode, --lsb/--msb); spi transfer CH BYTE...: exchange the
    bytes, print what came back.

    example: orfa spi bind 0 B 4; orfa spi transfer 0 0x03 0x00 0x00
    """
    with open_board(args) as board:
        spi = board.spi
        if args.spi_command == "bind":
            spi.bind(args.channel, _port(board, args.gpio_port), args.line)
        elif args.spi_command == "config":
            if args.div is None and args.mode is None and args.lsb is None:
                cfg = spi.config()
                f_cpu = getattr(board.map, "f_cpu", p.F_CPU)
                print("clock %d Hz (divider %d), mode %d, %s first" % (
                    f_cpu // 2 ** (cfg["clock_div"] + 1), cfg["clock_div"],
                    cfg["mode"], "LSB" if cfg["lsb_first"] else "MSB"))
                for ch, bound in sorted(cfg["channels"].items()):
                    print("channel %d: %s" % (ch, "unbound" if bound is None
                                              else "chip select P%s%d" % bound))
                return 0
            cfg = spi.config()
            spi.configure(clock_div=cfg["clock_div"] if args.div is None else args.div,
                          mode=cfg["mode"] if args.mode is None else args.mode,
                          lsb_first=cfg["lsb_first"] if args.lsb is None else args.lsb)
        else:
            print(hex_bytes(spi.transfer(args.channel, bytes(args.bytes))))
    return 0


# --- status ---------------------------------------------------------------------

def cmd_status(args) -> int:
    """status register, reset cause, failsafe

    The board's status register (the result of the last register access)
    with its meaning, why it reset since the causes were cleared, and the
    link-loss failsafe.

    example: orfa status --addr 0x10; orfa status --failsafe 200
    """
    with open_board(args) as board:
        if args.clear_reset:
            board.clear_reset_cause()
        if args.failsafe is not None:
            board.set_failsafe(args.failsafe)
        status = board.status()
        causes = board.reset_cause()
        failsafe = board.failsafe()
        where = _where(args, board)
    order = ["power", "external", "brownout", "watchdog", "jtag"]
    print("board        %s" % where)
    print("status       %02X %s: %s" % (int(status), status.name, status.text))
    print("reset cause  %s" % (", ".join(c for c in order if c in causes) or "none since cleared"))
    print("failsafe     %s" % ("off" if failsafe == 0 else "%d ms" % failsafe))
    return 0


# --- the parsers ------------------------------------------------------------------

def add_parsers(sub, common) -> None:
    command(sub, [common], cmd_drivers)
    command(sub, [common], cmd_servo,
            arg("channel", nargs="?", metavar="CH", help="channel number, or off (all)"),
            arg("us", nargs="?", metavar="US", help="width in microseconds, or off"),
            arg("--angle", nargs="?", type=_angle, const=READ, metavar="DEG",
                help="set the angle (DEG), or print it (no DEG)"),
            arg("--range", type=servo_range, metavar="MIN_US:MAX_US:MIN_DEG:MAX_DEG",
                help="the servo's range for --angle (default 1000:2000:-75:75)"))
    command(sub, [common], cmd_motor,
            arg("n", nargs="?", metavar="N", help="1 or 2, or stop (both)"),
            arg("duty", nargs="?", metavar="DUTY", help=DUTY_RANGE + ", or stop"),
            DUTY_RANGE=DUTY_RANGE)
    command(sub, [common], cmd_adc,
            arg("--channels", type=channel_list, metavar="LIST",
                help="turn on these channels, the others off (0-3,6; all; none; default all)"),
            arg("--ref", choices=("avcc", "aref", "internal"),
                help="the reference (default avcc)"),
            arg("--bits", type=int, choices=(8, 10), help="the resolution (default 10)"),
            arg("--vref", type=volts, metavar="V",
                help="the reference's volts (for aref; default 5.0 avcc, 2.56 internal)"),
            arg("--watch", nargs="?", type=interval, const=0.5, metavar="SECONDS",
                help="redraw the table every SECONDS (default 0.5)"),
            arg("--count", type=number, metavar="N", help="with --watch: stop after N tables"))
    command(sub, [common], cmd_gpio,
            arg("gpio_port", nargs="?", metavar="PORT", help="a port letter (A)"),
            arg("value", nargs="?", type=byte, metavar="VALUE"),
            arg("mask", nargs="?", type=byte, metavar="MASK"),
            arg("--output", type=byte, metavar="MASK", help="make these lines outputs"),
            arg("--input", type=byte, metavar="MASK", help="make these lines inputs"))
    _spi_actions(command(sub, [common], cmd_spi), common)
    command(sub, [common], cmd_status,
            arg("--clear-reset", action="store_true", help="clear the reset causes first"),
            arg("--failsafe", type=number, metavar="MS",
                help="set the failsafe first: MS milliseconds, 0 off"))


def _spi_actions(cmd, common) -> None:
    """spi's own actions: bind, config, transfer."""
    spi = cmd.add_subparsers(dest="spi_command", metavar="ACTION")
    spi.required = True
    bind = spi.add_parser("bind", parents=[common], help="a chip select line for a channel",
                          epilog="example: orfa spi bind 0 B 4")
    bind.add_argument("channel", type=number, metavar="CH")
    bind.add_argument("gpio_port", metavar="PORT")
    bind.add_argument("line", type=number, metavar="LINE")
    conf = spi.add_parser("config", parents=[common], help="bus settings",
                          epilog="example: orfa spi config --div 6 --mode 3")
    conf.add_argument("--div", type=number, metavar="N",
                      help="clock divider 0..6: SCK = F_CPU / 2^(N+1)")
    conf.add_argument("--mode", type=number, metavar="M", help="SPI mode 0..3")
    order = conf.add_mutually_exclusive_group()
    order.add_argument("--lsb", action="store_true", default=None, help="LSB first")
    order.add_argument("--msb", dest="lsb", action="store_false", help="MSB first")
    xfer = spi.add_parser("transfer", parents=[common], help="exchange bytes",
                          epilog="example: orfa spi transfer 0 0x03 0x00 0x00")
    xfer.add_argument("channel", type=number, metavar="CH")
    xfer.add_argument("bytes", type=byte, nargs="+", metavar="BYTE")
