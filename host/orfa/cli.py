"""Command line: `python3 -m orfa sim ...` and `python3 -m orfa request ...`."""

from __future__ import annotations

import argparse
import signal
import sys
import time
from typing import List, Optional, TextIO

from . import flash, protocol as p
from .gateway import Gateway
from .sim import BOARDS, SimBoard, SimError


def _int(text: str) -> int:
    return int(text, 0)


def expects_reply(line: str) -> bool:
    """Whether the gateway answers this line (empty and comment lines: no)."""
    return bool(line.strip(" ")) and not line.startswith("#")


def terminal(gw: Gateway, stdin: TextIO, stdout: TextIO) -> int:
    """A line console: each input line is a request, its reply is printed."""
    interactive = stdin.isatty()
    while True:
        if interactive:
            stdout.write("orfa> ")
            stdout.flush()
        line = stdin.readline()
        if not line:
            return 0
        line = line.rstrip("\r\n")
        if not expects_reply(line):
            if line.strip(" "):
                gw.send(p.encode_request(line))
            continue
        try:
            reply = gw.request(line)
        except (p.OrfaError, ValueError) as exc:
            reply = "host: %s" % exc
        stdout.write(reply + "\n")
        stdout.flush()


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
    if addr & 1 or not 0x10 <= addr <= 0xEE:
        raise argparse.ArgumentTypeError("%r: ADDR must be even, 0x10..0xEE" % text)
    return (parts[0], addr, parts[2] if len(parts) == 3 and parts[2] else None)


def cmd_sim(args) -> int:
    try:
        board = SimBoard(args.board, eeproms=args.eeprom, trace=False,
                         firmware=args.firmware, slaves=args.slave,
                         control=args.autobaud).start()
    except (SimError, ValueError) as exc:
        print("orfa: %s" % exc, file=sys.stderr)
        return 2
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1) or _raise_interrupt())
    try:
        print(board.port, flush=True)
        if args.terminal:
            with board.gateway(args.baud, autobaud=args.autobaud) as gw:
                return terminal(gw, sys.stdin, sys.stdout)
        while board.running:
            time.sleep(0.2)
        print("orfa: the simulator stopped: %s" % board.stderr, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0
    finally:
        board.stop()


def _raise_interrupt():
    raise KeyboardInterrupt


def cmd_request(args) -> int:
    with Gateway(args.port, baudrate=args.baud, timeout=args.timeout,
                 autobaud=args.autobaud) as gw:
        for line in args.requests:
            try:
                reply = gw.request(line)
            except (p.OrfaError, ValueError) as exc:
                print("orfa: %s" % exc, file=sys.stderr)
                return 1
            print(reply)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="orfa", description="ORFA host tools")
    sub = parser.add_subparsers(dest="command", required=True)

    sim = sub.add_parser("sim", help="run a simulated board and print its port")
    sim.add_argument("--board", choices=BOARDS, default="m32d")
    sim.add_argument("--eeprom", type=_int, action="append", default=[],
                     metavar="ADDR", help="attach a 24C02-like EEPROM (repeatable)")
    sim.add_argument("--firmware", help="ELF to run (default: build/<board>-gate/orfa.elf)")
    sim.add_argument("--terminal", action="store_true",
                     help="also open a line console on the board")
    sim.add_argument("--slave", type=slave_spec, action="append", default=[],
                     metavar="BOARD:ADDR[:ELF]",
                     help="a slave board on the bus (repeatable); ELF defaults to"
                          " build/robot/<board>-<ADDR>/orfa.elf (make robot) if"
                          " built, else build/<board>-slave/orfa.elf")
    sim.add_argument("--baud", type=int, default=p.DEFAULT_BAUD,
                     help="the console's rate (default %(default)s)")
    sim.add_argument("--autobaud", action="store_true",
                     help="the console opens with the BAUD=auto preamble (eight CRs,"
                          " 20 ms of simulated quiet)")
    sim.set_defaults(func=cmd_sim)

    req = sub.add_parser("request", help="send requests, print the replies")
    req.add_argument("--port", required=True, help="serial port or pyserial URL")
    req.add_argument("--baud", type=int, default=p.DEFAULT_BAUD)
    req.add_argument("--autobaud", action="store_true",
                     help="send the BAUD=auto preamble first (eight CRs, then 20 ms quiet)")
    req.add_argument("--timeout", type=float, default=2.0)
    req.add_argument("requests", nargs="+", metavar="REQUEST")
    req.set_defaults(func=cmd_request)

    flash.add_parser(sub)
    return parser


def main(argv: Optional[List[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)
