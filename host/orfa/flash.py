"""`orfa flash`: write a board's firmware or fuses with avrdude.

The same command lines as `make flash` and `make fuses` (docs/flashing.md):

    avrdude -c usbasp -p m32 [-P PORT] -U flash:w:build/m32d-gate/orfa.hex:i
    avrdude -c usbasp -p m32 [-P PORT] -U lfuse:w:0xff:m -U hfuse:w:0xd9:m

The argv is built by pure functions; `run` finds avrdude and runs it, its
output passed through.
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import List, Optional, Sequence

from . import boardmap, ihex
from .errors import FlashError
from .locate import firmware_dirs, firmware_path, gateway_firmware

PROGRAMMER = "usbasp"
MODES = ("gate", "slave")
#: The bus address of the packaged slave builds, build/<board>-slave/ (the
#: Makefile's ADDR default; `pip install .` ships these).
SLAVE_ADDR = 0x10
#: Exit status when avrdude, the firmware or the board is missing.
EXIT_SETUP = 2
#: Exit status when avrdude ran and failed.
EXIT_AVRDUDE = 1


def board_map(board: str) -> boardmap.BoardMap:
    """The board's map, whose avrdude part and fuses come from its board.mk
    (BOARD_AVRDUDE_PART, BOARD_FUSES), as `make flash`/`make fuses` read them."""
    if board not in boardmap.BOARDS:
        raise FlashError("no such board %r: one of %s" % (board, ", ".join(boardmap.BOARDS)))
    return boardmap.load(board)


def avrdude_argv(part: str, programmer: str = PROGRAMMER, port: Optional[str] = None,
                 avrdude: str = "avrdude", extra: Sequence[str] = ()) -> List[str]:
    """avrdude, the programmer, the part, the port if one is given, extras."""
    argv = [avrdude, "-c", programmer, "-p", part]
    if port:
        argv += ["-P", port]
    return argv + list(extra)


def flash_argv(board: str, hex_path: str, **kw) -> List[str]:
    """Write `hex_path` (Intel HEX) to the board's flash."""
    return avrdude_argv(board_map(board).avrdude_part, **kw) + ["-U", "flash:w:%s:i" % hex_path]


def fuses_argv(board: str, **kw) -> List[str]:
    """Write the board's fuses, in board.mk's order."""
    bmap = board_map(board)
    argv = avrdude_argv(bmap.avrdude_part, **kw)
    for name, value in bmap.fuses.items():
        argv += ["-U", "%s:w:0x%02x:m" % (name, value)]
    return argv


def build_hex(board: str, mode: str) -> Path:
    """The .hex next to the board's ELF (`make`'s build/<board>-<mode>/orfa.hex)."""
    return firmware_path(board, mode).with_suffix(".hex")


def built_address(elf: Path) -> int:
    """The bus address a slave build answers on: the ORFA_ADDR of make's
    `flags` file next to the ELF, SLAVE_ADDR where there is none (the
    installed package's copies, built with make's default)."""
    try:
        words = (elf.parent / "flags").read_text().split()
    except OSError:
        return SLAVE_ADDR
    for word in words:
        if word.startswith("-DORFA_ADDR="):
            try:
                return int(word.split("=", 1)[1], 0)
            except ValueError:
                break
    return SLAVE_ADDR


def slave_elf(board: str, addr: int) -> Path:
    """The slave build of `board` that answers on `addr`: <board>-slave/
    (what `make flash MODE=slave` writes) when it was built for that
    address, else the test robot's robot/<board>-0x<ADDR>/ (`make robot`);
    a FlashError says how to build one."""
    if not boardmap.address_ok(addr):
        raise FlashError("--addr 0x%02X: a slave's 8-bit bus address is %s"
                         % (addr, boardmap.ADDRESS_TEXT))
    for d in firmware_dirs():
        packaged = d / ("%s-slave" % board) / "orfa.elf"
        if packaged.is_file() and built_address(packaged) == addr:
            return packaged
        robot = d / "robot" / ("%s-0x%02X" % (board, addr)) / "orfa.elf"
        if robot.is_file():
            return robot
    raise FlashError("no %s slave build at 0x%02X (the packaged one answers on 0x%02X):"
                     " build it with `make BOARD=%s MODE=slave ADDR=0x%02X`, or give --hex FILE"
                     % (board, addr, SLAVE_ADDR, board, addr))


def firmware_hex(board: str, mode: str, given: Optional[str], tmpdir: str,
                 addr: Optional[int] = None, rate=None) -> Path:
    """The Intel HEX to write: `given` (an ELF is converted), else the build's
    .hex if it is as new as its ELF, else that ELF converted (a .hex older
    than its ELF, or none: an ELF given by ORFA_FIRMWARE alone). Conversions go to `tmpdir`.
    With `addr` (slave mode): the slave build that answers on it (slave_elf).
    With `rate` (gate mode: a serial rate or "auto"): the gateway built for
    it (orfa.locate.gateway_firmware: build/<board>-gate-<rate>/)."""
    if given:
        path = Path(given)
        try:
            with path.open("rb") as f:
                head = f.read(4)
        except OSError as exc:
            raise FlashError("cannot read %s: %s" % (given, exc.strerror)) from None
        if ihex.is_elf(head):
            return _converted(path, tmpdir, board_map(board))
        if head[:1] != b":":
            raise FlashError("%s is neither Intel HEX nor an ELF file" % given)
        return path
    if addr is not None:
        elf = slave_elf(board, addr)
        hex_path = elf.with_suffix(".hex")
    elif rate is not None:
        try:
            elf = gateway_firmware(board, rate)
        except ValueError as exc:
            raise FlashError(str(exc)) from None
        hex_path = elf.with_suffix(".hex")
    else:
        elf = firmware_path(board, mode)
        hex_path = build_hex(board, mode)
    if hex_path.is_file() and (not elf.is_file()
                               or hex_path.stat().st_mtime >= elf.stat().st_mtime):
        return _near(hex_path)
    if elf.is_file():
        return _converted(elf, tmpdir, board_map(board))
    addr_var = " ADDR=0x%02X" % SLAVE_ADDR if mode == "slave" else ""
    raise FlashError("no firmware for %s %s: build it with `make BOARD=%s MODE=%s%s`,"
                     " or give --hex FILE" % (board, mode, board, mode, addr_var))


def _near(path: Path) -> Path:
    """`path` relative to the current directory when it lies below it, so
    `orfa flash` in the repository runs the very command `make flash` runs."""
    try:
        return path.relative_to(Path.cwd())
    except ValueError:
        return path


def _converted(elf: Path, tmpdir: str, board: boardmap.BoardMap) -> Path:
    """The ELF as Intel HEX in tmpdir; an ELF whose note names another MCU
    than the board's is refused (a HEX file says nothing of its MCU)."""
    try:
        data = elf.read_bytes()
        text = ihex.elf_to_ihex(data)
    except OSError as exc:
        raise FlashError("cannot read %s: %s" % (elf, exc.strerror)) from None
    except ihex.ElfError as exc:
        raise FlashError("%s: %s" % (elf, exc)) from None
    device = ihex.elf_device(data)
    if device is not None and device != board.mcu:
        raise FlashError("%s was built for the %s, not the %s's %s (--board)"
                         % (elf, device, board.board, board.mcu))
    out = Path(tmpdir) / (elf.stem + ".hex")
    out.write_text(text)
    return out


def find_avrdude(name: str) -> str:
    """The path of avrdude (`name` may be a path or a name on PATH)."""
    found = shutil.which(name)
    if not found:
        raise FlashError("%s not found%s: install avrdude (tools/setup.sh, or"
                         " `apt install avrdude`) or give --avrdude PATH"
                         % (name, "" if os.sep in name else " on PATH"))
    return found


def run(argv: List[str]) -> int:
    """Run avrdude with its output passed through; its exit status."""
    exe = find_avrdude(argv[0])
    try:
        return subprocess.run([exe] + argv[1:]).returncode
    except OSError as exc:
        raise FlashError("cannot run %s: %s" % (exe, exc.strerror)) from None


def cmd_flash(args) -> int:
    kw = dict(programmer=args.programmer, port=args.port, avrdude=args.avrdude)
    if args.addr is not None:
        clash = ("--mode gate" if args.mode != "slave" else "--hex" if args.hex
                 else "--fuses" if args.fuses else None)
        if clash:
            print("orfa: --addr picks the slave build that answers on it: it goes with"
                  " --mode slave, not %s" % clash, file=sys.stderr)
            return EXIT_SETUP
    if args.rate is not None:
        clash = ("--mode slave" if args.mode == "slave" else "--hex" if args.hex
                 else "--fuses" if args.fuses else None)
        if clash:
            print("orfa: --rate picks the gateway built for that serial rate: it goes with"
                  " --mode gate, not %s" % clash, file=sys.stderr)
            return EXIT_SETUP
    try:
        with tempfile.TemporaryDirectory(prefix="orfa-flash-") as tmpdir:
            if args.fuses:
                argv = fuses_argv(args.board, **kw)
            else:
                hex_path = firmware_hex(args.board, args.mode, args.hex, tmpdir, args.addr,
                                        args.rate)
                argv = flash_argv(args.board, str(hex_path), **kw)
            if args.dry_run:
                print(shlex.join(argv))
                return 0
            status = run(argv)
    except FlashError as exc:
        print("orfa: %s" % exc, file=sys.stderr)
        return EXIT_SETUP
    if status != 0:
        print("orfa: avrdude failed (exit status %d)" % status, file=sys.stderr)
        return EXIT_AVRDUDE
    return 0


def _number(text: str) -> int:
    try:
        return int(text, 0)
    except ValueError:
        import argparse
        raise argparse.ArgumentTypeError("%r is not a number (0x10)" % text) from None


def _rate(text: str):
    """--rate: "auto", or a rate as --baud takes it (cli.common.baud_rate;
    whether a gateway is built for it is firmware_hex's to say)."""
    import argparse
    from .cli.common import baud_rate
    if text == "auto":
        return text
    try:
        return baud_rate(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError("%r is not a serial rate (460800) or auto"
                                         % text) from None


def add_parser(subparsers) -> None:
    """Register `flash` on an argparse subparsers object."""
    p = subparsers.add_parser(
        "flash", help="write a board's firmware (or fuses) with avrdude",
        description="Write the firmware's Intel HEX to a board through an ISP"
                    " programmer with avrdude, as `make flash` does; --fuses"
                    " writes the board's fuses instead, as `make fuses`.")
    p.add_argument("--board", choices=boardmap.BOARDS, default="m32d")
    p.add_argument("--mode", choices=MODES, default="gate",
                   help="which build (default %%(default)s); a slave's bus address"
                        " is the one it was built with: 0x%02X for the packaged"
                        " build/<board>-slave (make's ADDR default)" % SLAVE_ADDR)
    p.add_argument("--addr", type=_number, metavar="ADDR",
                   help="with --mode slave: the 8-bit bus address the slave is to answer"
                        " on (default: the packaged build's, 0x%02X); another address"
                        " takes the test robot's build robot/<board>-<ADDR> (make robot)"
                        " or says how to build one" % SLAVE_ADDR)
    p.add_argument("--rate", type=_rate, metavar="BAUD",
                   help="with --mode gate: the gateway built for this serial rate"
                        " (230400, 460800, auto: the packaged builds, make gate-rates;"
                        " in the source tree any rate make takes is built first);"
                        " default: the 115200 build")
    what = p.add_mutually_exclusive_group()
    what.add_argument("--hex", metavar="FILE",
                      help="the Intel HEX (or ELF, converted to a temporary .hex)"
                           " to write (default: the build's"
                           " build/<board>-<mode>/orfa.hex, or its ELF)")
    p.add_argument("--programmer", default=PROGRAMMER,
                   help="avrdude's programmer, -c (default %(default)s)")
    p.add_argument("--port", help="avrdude's -P (none by default: avrdude's own)")
    what.add_argument("--fuses", action="store_true",
                   help="write the board's fuses instead of the firmware")
    p.add_argument("--avrdude", default=os.environ.get("AVRDUDE") or "avrdude",
                   metavar="PATH", help="the avrdude to run (default: $AVRDUDE or"
                                        " avrdude on PATH)")
    p.add_argument("--dry-run", action="store_true",
                   help="print the avrdude command and exit")
    p.set_defaults(func=cmd_flash)
