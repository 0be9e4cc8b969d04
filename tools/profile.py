#!/usr/bin/env python3
"""Where a gateway's cycles go in the robot control loop
(examples/control_loop.py): a table of simulated cycles a step by source
file, function or line, the board's work a step against the step's wire
time.

    python3 tools/profile.py [--board m32d|m128s] [--baud 230400] [--steps N]
                             [--by file|function|line] [--top N]

The gateway is built with debug information (build/profile/BOARD-BAUD,
`make FW_DEBUG=-g`: the same code but for a few calls the linker relaxes
differently, 8 bytes on the M32-D) and runs in the simulator with an
MPU-6050 on its bus, at real time (orfa-sim --real-time). The pipelined
loop (control_loop.timed(), 2 steps submitted ahead) runs WARMUP steps to
fill its pipeline, then STEPS more; the simulator's `profile` request
(docs/simulator.md) counts every cycle from the moment the host has step
WARMUP-1's inputs to the moment it has the last step's (the span
control_loop.timed() measures for make bench). Cycles at lines marked
`profile: idle` in the firmware (the main loop looking for a character,
uart_putc() waiting for room) are the board's idle time, not its work.
Figures differ by a few hundred cycles from run to run: the timers' phase at
the start differs.

Exit status 0, 1 with one line on stderr (a build or a run that failed), 2
for wrong arguments.
"""

import argparse
import bisect
import collections
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "host"), str(ROOT / "examples")]

import control_loop as cl  # noqa: E402
from orfa import Board, OrfaError  # noqa: E402
from orfa.gateway import Gateway  # noqa: E402
from orfa.locate import make_gateway  # noqa: E402
from orfa.protocol import BAUD_RATES, DEFAULT_BAUD, F_CPU  # noqa: E402
from orfa.sim import SimBoard  # noqa: E402
from orfa.simctl import SimControlError  # noqa: E402

#: the control loop's rates (make bench's): the default and those above it
RATES = tuple(r for r in BAUD_RATES if r >= DEFAULT_BAUD)
IDLE_MARK = "profile: idle"
#: steps run before the profile starts (the pipeline filled)
WARMUP = 5


class ProfileError(Exception):
    pass


def build(board, baud):
    try:
        return make_gateway(board, baud, "build/profile/%s-%d" % (board, baud), "FW_DEBUG=-g")
    except ValueError as exc:
        raise ProfileError(str(exc)) from None


def profile_steps(board, baud, steps, elf):
    """({byte address: cycles}, simulated cycles, characters in and out a
    step) of `steps` steps of the pipelined loop after WARMUP."""
    sim = cl.simulated_board(board, baud, firmware=str(elf))
    try:
        with Gateway(sim.port, baudrate=baud, timeout=10) as gw:
            loop = cl.ControlLoop(Board(gw))
            loop.setup()
            ctl = sim.control
            got = []

            def clock():  # the timed window's ends: the profile on, then read
                if not got:
                    r = ctl.requests(["profile on", "time"])
                    got.append(None)
                    return int(r[1])
                r = ctl.requests(["time", "profile", "profile off"])
                got.append({int(a, 16): int(c) for a, _, c in
                            (x.partition(":") for x in r[1].split()[1:])})
                return int(r[0])

            cycles, _ = cl.timed(loop, WARMUP + steps, True, clock, cl.check_sim_inputs, WARMUP)
            sent, received = loop.last.wire()
    finally:
        sim.stop()
    return got[1], cycles, sent, received


def locate(elf, addrs):
    """{address: (file, line)} from the ELF's debug lines (where code is
    inlined, the inlined function's line)."""
    out = subprocess.run(["avr-addr2line", "-a", "-e", str(elf)] + ["%x" % a for a in addrs],
                         capture_output=True, text=True, check=True).stdout.splitlines()
    where = {}
    for k in range(0, len(out) - 1, 2):
        path, _, line = out[k + 1].partition(":")
        line = line.split(" ")[0]
        try:
            path = str(Path(path).resolve().relative_to(ROOT))
        except ValueError:
            path = "??"
        where[int(out[k], 16)] = (path, int(line) if line.isdigit() else 0)
    return where


def symbols(elf):
    syms = []
    out = subprocess.run(["avr-nm", "-n", str(elf)], capture_output=True, text=True,
                         check=True).stdout
    for line in out.splitlines():
        f = line.split()
        if len(f) == 3 and f[1] in "tTwW":
            syms.append((int(f[0], 16), f[2]))
    return syms


def classify(counts, elf, by):
    """{row: cycles} and the idle cycles."""
    where = locate(elf, sorted(counts))
    syms = symbols(elf)
    starts = [a for a, _ in syms]
    sources = {}
    rows, idle = collections.Counter(), 0
    for a, c in counts.items():
        path, line = where.get(a, ("??", 0))
        outer = syms[bisect.bisect_right(starts, a) - 1][1] if starts and a >= starts[0] else "??"
        if path != "??":
            if path not in sources:
                sources[path] = (ROOT / path).read_text(errors="replace").splitlines()
            text = sources[path][line - 1] if 0 < line <= len(sources[path]) else ""
            if IDLE_MARK in text:
                idle += c
                continue
        isr = outer.startswith("__vector_")
        if path == "??":
            # libgcc's and avr-libc's code (prologues, multiplies, memcpy)
            key = "(no source line) " + outer if outer != "__vectors" else "(the vector table)"
        elif by == "file":
            key = path + (" (interrupts)" if isr else "")
        elif by == "function":
            key = outer.split(".")[0]  # the symbol (the compiler's suffix off)
        else:
            key = "%s:%d" % (path, line)
        rows[key] += c
    return rows, idle


def main(argv=None):
    ap = argparse.ArgumentParser(prog="profile", description=__doc__.split("\n\n")[0])
    ap.add_argument("--board", choices=("m32d", "m128s"), default="m32d")
    ap.add_argument("--baud", type=int, choices=RATES, default=230400)
    ap.add_argument("--steps", type=int, default=40, metavar="N",
                    help="steps profiled (after %d to fill the pipeline), default 40" % WARMUP)
    ap.add_argument("--by", choices=("file", "function", "line"), default="file")
    ap.add_argument("--top", type=int, default=25, metavar="N",
                    help="rows shown (the rest summed in one), default 25")
    a = ap.parse_args(argv)
    if a.top < 1 or a.steps < 1:
        ap.error("--top, --steps: 1 or more")
    try:
        elf = build(a.board, a.baud)
        counts, cycles, rx, tx = profile_steps(a.board, a.baud, a.steps, elf)
        rows, idle = classify(counts, elf, a.by)
    except (ProfileError, OrfaError, SimControlError, OSError, ValueError,
            subprocess.CalledProcessError) as e:
        print("profile: %s" % e, file=sys.stderr)
        return 1
    total = sum(counts.values())
    work = total - idle
    n = a.steps
    wire = n * max(rx, tx) * 10 * F_CPU / a.baud
    name = {"m32d": "M32-D", "m128s": "M128-S"}[a.board]
    print("%s gateway at %d baud: %d steps of the pipelined control loop (%d characters in, "
          "%d out a step); cycles a step" % (name, a.baud, n, rx, tx))
    width = max([len(k) for k in rows] + [24])
    shown = sorted(rows.items(), key=lambda kv: -kv[1])
    rest = shown[a.top:]
    shown = shown[:a.top] + ([("(%d more)" % len(rest), sum(c for _, c in rest))] if rest else [])
    print("%-*s %8s %6s" % (width, a.by, "cycles", "work"))
    for key, c in shown:
        print("%-*s %8.0f %5.1f%%" % (width, key, c / n, 100.0 * c / work))
    print("%-*s %8.0f" % (width, "idle (lines marked `%s`)" % IDLE_MARK, idle / n))
    print("work a step %.0f cycles, the step's wire %.0f: the board's time allows %.1f %% of the "
          "wire; the loop made %.1f %%" % (work / n, wire / n, min(100.0, 100.0 * wire / work),
                                          100.0 * wire / cycles))
    return 0


if __name__ == "__main__":
    sys.exit(main())
