"""`orfa sim`: run a simulated board or robot until interrupted (or for a
console on it), printing its serial port's path."""

from __future__ import annotations

import argparse
import os
import signal
import sys

from .. import protocol as p
from ..sim import BOARDS, SimError
from .common import UsageError, add_sim_devices, arg, baud_rate, command, sim_board
from .common import adc_spec, eeprom_spec, slave_spec  # noqa: F401 (here before)
from .console import run_console


def _raise_interrupt(*_):
    raise KeyboardInterrupt


def _link(target, path: str) -> None:
    """A symlink at path to target (the simulator's control socket)."""
    try:
        os.symlink(str(target), path)
    except OSError as exc:
        raise UsageError("cannot make %s: %s" % (path, exc.strerror)) from None


def cmd_sim(args) -> int:
    """run a simulated board or robot, print its port

    Run build/sim/orfa-sim on a board's gateway firmware (with --slave: a
    robot, the slave boards on its I2C bus) and print the path of its
    serial port on the first line (with --control, the control socket's on
    the second). Runs until Ctrl-C or SIGTERM (exit 0), or with --terminal
    for a console on the board until the end of its input (then the lines
    say what they are: `serial port: PATH`). Bus addresses are the
    protocol's 8-bit form. docs/simulator.md describes the devices and the
    control socket.

    example: orfa sim --board m32d --eeprom 0xA0 --slave m128s:0x10 --terminal
    """
    control = args.control is not None or args.autobaud
    extra = []
    if args.trace:
        extra += ["--trace", args.trace]
    if args.vcd:
        extra += ["--vcd", args.vcd]
    try:
        board = sim_board(args.board, args, trace=False,
                          firmware=args.firmware,
                          control=control, extra_args=extra).start()
    except (SimError, ValueError) as exc:
        raise UsageError(getattr(exc, "refused", None) or str(exc)) from None
    link = None
    signal.signal(signal.SIGTERM, _raise_interrupt)
    # for a program, the bare paths (`port=$(orfa sim | head -1)`); with
    # --terminal a person reads them, so each says what it is
    port_label, control_label = (("serial port:    ", "control socket: ") if args.terminal
                                 else ("", ""))
    try:
        print(port_label + board.port, flush=True)
        if args.control is not None:
            link = args.control or None
            if link:
                _link(board.control_path, link)
            print(control_label + str(link or board.control_path), flush=True)
        if args.terminal:
            with board.gateway(args.baud, autobaud=args.autobaud) as gw:
                return run_console(gw)
        board.proc.wait()                  # until it ends (or SIGTERM, Ctrl-C)
        print("orfa: the simulator stopped: %s" % board.stderr.strip(), file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0
    finally:
        board.stop()
        if link and os.path.islink(link):
            os.unlink(link)


def add_parsers(sub, common) -> None:
    cmd = command(sub, [], cmd_sim, arg("--board", choices=BOARDS, default="m32d",
                                        help="the gateway's board (default %(default)s)"))
    add_sim_devices(cmd)
    cmd.add_argument("--firmware", help="ELF to run (default: the board's gateway built for"
                     " --baud: build/<board>-gate/orfa.elf at 115200; with --autobaud"
                     " build/<board>-gate-auto/orfa.elf)")
    cmd.add_argument("--control", nargs="?", const="", metavar="PATH",
                     help="open the control socket (at PATH if given) and print its path")
    cmd.add_argument("--trace", metavar="FILE", help="write the bus and serial trace to FILE")
    cmd.add_argument("--vcd", metavar="FILE", help="write every pin's waveform to FILE (VCD)")
    cmd.add_argument("--terminal", action="store_true",
                     help="also open a line console on the board (as orfa console)")
    cmd.add_argument("--baud", type=baud_rate, default=p.DEFAULT_BAUD,
                     help="the gateway's serial rate, its firmware built for it, and the"
                          " console's (default %(default)s)")
    cmd.add_argument("--autobaud", action="store_true",
                     help="run the BAUD=auto gateway (build/<board>-gate-auto); the console"
                          " opens with its preamble (eight CRs, 20 ms of simulated quiet)"
                          " at --baud")
