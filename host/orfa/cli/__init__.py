"""The `orfa` command: `orfa [--port URL | --sim BOARD] COMMAND ...`.

One module per group of commands: bus (version, scan, read, write, transfer,
request), devices (drivers and the driver clients), console, simulate (sim),
plot, dash (the live web page);
`flash` comes from orfa.flash when it is there. Exit status: 0 ok, 1 an
ERROR reply or a device, bus or serial failure, 2 a usage error (bad
arguments, a port that cannot be opened), 130 Ctrl-C.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import os
import sys
from typing import List, Optional

import serial

from .. import __version__
from .. import protocol as p
from ..sim import BOARDS
from . import bus, console, dash, devices, plot, simulate
from .common import (ADDRESS_RULE, MAX_TIMEOUT_S, PORT_ENV, UsageError, add_sim_devices,
                     baud_rate, explain, number, seconds)

EXIT_OK, EXIT_FAILED, EXIT_USAGE, EXIT_INTERRUPTED = 0, 1, 2, 130


def _connection_options(parser, suppress: bool) -> None:
    """--port/--sim and friends: before the command (with defaults) and
    after it (suppressed defaults, so they do not undo the ones before)."""
    def default(value):
        return argparse.SUPPRESS if suppress else value
    group = parser.add_argument_group("the board")
    where = group.add_mutually_exclusive_group()
    where.add_argument("--port", "-p", metavar="URL", default=default(None),
                       help="serial port or pyserial URL (/dev/ttyUSB0, socket://host:port);"
                            " default $%s" % PORT_ENV)
    where.add_argument("--sim", choices=BOARDS, metavar="BOARD", default=default(None),
                       help="start a simulated board (%s) for this one command; --eeprom, --part,"
                            " --slave, --adc, --spi (before the command) add devices"
                            % "|".join(BOARDS))
    group.add_argument("--baud", type=baud_rate, default=default(p.DEFAULT_BAUD),
                       help="serial rate, the gateway's BAUD (default %d; its builds run %d..%d);"
                            " --sim runs the gateway built for it"
                            % (p.DEFAULT_BAUD, p.BAUD_RATES[0], p.BAUD_RATES[-1]))
    group.add_argument("--timeout", type=seconds, default=default(2.0), metavar="S",
                       help="seconds to wait for a reply, above 0, at most %g (default 2)"
                            % MAX_TIMEOUT_S)
    group.add_argument("--addr", type=number,
                       default=default(None), metavar="A",
                       help="the board the driver commands talk to: a slave's bus"
                            " address (default: the gateway itself)")
    group.add_argument("--7bit", dest="seven_bit", action="store_true",
                       default=default(False),
                       help="addresses are 7-bit (i2c-tools' form), not the protocol's 8-bit")
    group.add_argument("--autobaud", action="store_true", default=default(False),
                       help="open the line with the BAUD=auto preamble (eight CRs, 20 ms quiet);"
                            " --sim runs the board's BAUD=auto gateway")


class Parser(argparse.ArgumentParser):
    """argparse with a usage error in one line (the command and the
    problem, where to read more), exit 2: the synopsis argparse prints
    first is five lines long and hides what was wrong."""

    def error(self, message: str):
        self.exit(EXIT_USAGE, "%s: error: %s (%s --help)\n" % (self.prog, message, self.prog))


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="orfa", description="ORFA host tools: talk to an ORFA gateway and the boards"
                                 " on its I2C bus, or simulate them. " + ADDRESS_RULE,
        epilog="examples: orfa --sim m32d scan; orfa --port /dev/ttyUSB0 servo 3 1500;"
               " orfa COMMAND --help. Exit status: 0 ok, 1 an ERROR reply or a device"
               " or bus failure, 2 a usage error or a port that cannot be opened.")
    parser.add_argument("--version", action="version", version="orfa %s" % __version__)
    _connection_options(parser, suppress=False)
    sim_devices = parser.add_argument_group("devices of the --sim board")
    add_sim_devices(sim_devices, suppress=True)
    common = Parser(add_help=False)
    _connection_options(common, suppress=True)

    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    bus.add_parsers(sub, common)
    devices.add_parsers(sub, common)
    console.add_parsers(sub, common)
    simulate.add_parsers(sub, common)
    plot.add_parsers(sub, common, run=main)
    dash.add_parsers(sub, common)
    if importlib.util.find_spec("orfa.flash") is not None:
        importlib.import_module("orfa.flash").add_parser(sub)
    return parser


def main(argv: Optional[List[str]] = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except UsageError as exc:
        print("orfa: %s" % exc, file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # the reader of our output went away (`orfa servo | head -3`): no
        # message, and none from the interpreter's final flush either
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_FAILED
    except p.OrfaError as exc:
        print("orfa: %s" % explain(exc), file=sys.stderr)
        return EXIT_FAILED
    except (serial.SerialException, OSError) as exc:
        print("orfa: serial line: %s" % exc, file=sys.stderr)
        return EXIT_FAILED
    except ValueError as exc:
        print("orfa: %s" % exc, file=sys.stderr)
        return EXIT_USAGE
