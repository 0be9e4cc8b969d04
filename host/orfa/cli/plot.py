"""`orfa plot`: draw servo pulses, motor PWM, chip selects and bus activity
with matplotlib, from the simulator's VCD (`orfa plot TRACE.vcd`) or from a
live simulated board through its control socket (`orfa plot --sim BOARD`,
`orfa plot --control PATH`), with the serial lines' bytes and the I2C
bus's frames (wires `sda` and `scl`) decoded on them. docs/plot.md."""

from __future__ import annotations

import argparse
import fnmatch
import os
import re
import shlex
import sys
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from .. import boardmap, decode, vcd, waves
from .. import plot as drawing
from ..sim import SimError
from ..simctl import SimControl, SimControlError, parse_edges
from .common import UsageError, command, env_port, sim_board

DEFAULT_FOR_US = 50000           # live: 50 ms of simulated time, 2.5 servo frames
MAX_DEFAULT_ROWS = 12

# the default rows, in this order: what a person looks at first
_RANK = {"SERVO_SIGNAL": 0, "SERVO": 0, "MOTOR_PWM": 1, "MOTOR_DIR": 1, "SPI_SS": 2, "SPI_SCK": 2,
         "SPI_MOSI": 2, "SPI_MISO": 2, "I2C_BUSY": 3, "TWI_SCL": 3, "TWI_SDA": 3, "UART_RX": 4,
         "UART_TX": 4}
_HIDDEN = {"SERVO_CLK", "SERVO_RST"}   # the M128-S's counter lines: its servoN rows show the pulses
#: Lines whose pulses come when there is something to send (a transaction,
#: a byte): their rows give widths and a count, no period or duty.
_NOT_PERIODIC = {"I2C_BUSY", "TWI_SCL", "TWI_SDA", "UART_RX", "UART_TX", "SPI_SS", "SPI_SCK",
                 "SPI_MOSI", "SPI_MISO"}
#: The I2C bus's own wires in a capture (the lines every board's TWI is on).
BUS_WIRES = {"sda": "TWI_SDA", "scl": "TWI_SCL"}


def parse_time(text: str) -> float:
    """`1500`, `1500us`, `1.5ms`, `0.02s` -> microseconds."""
    m = re.fullmatch(r"\s*(\d+(?:\.\d*)?|\.\d+)\s*(us|ms|s)?\s*", text)
    if not m:
        raise argparse.ArgumentTypeError("%r: a time like 1500, 1500us, 1.5ms or 0.02s" % text)
    scale = {"us": 1, None: 1, "ms": 1000, "s": 1000000}[m.group(2)]
    return float(m.group(1)) * scale


class Namer:
    """Which board each signal belongs to (a slave's carry its address:
    `10/servo3`), and what its pin does there, from the board maps."""

    def __init__(self, names: Sequence[str], boards: Optional[Dict[str, str]] = None):
        """boards: signal prefix ("" the gateway, "10") -> board name, where
        known (the VCD says, or --board); the others are told by their pins."""
        groups: Dict[str, List[str]] = {}
        for name in names:
            prefix, _, _ = name.rpartition("/")
            groups.setdefault(prefix, []).append(name)
        boards = boards or {}
        self.maps = {prefix: boardmap.load(boards[prefix]) if prefix in boards else _guess(group)
                     for prefix, group in groups.items()}
        #: the capture has the bus's own wires: the TWI pins carry the same lines
        self.bus_wires = all(wire in names for wire in BUS_WIRES)

    def _split(self, name: str) -> Tuple[str, str]:
        prefix, _, local = name.rpartition("/")
        return prefix, local

    def functions(self, name: str) -> List[Tuple[str, int]]:
        prefix, local = self._split(name)
        m = self.maps.get(prefix)
        if re.fullmatch(r"servo\d+", local):
            return [("SERVO_SIGNAL", int(local[5:]))]
        if local == "i2c":
            return [("I2C_BUSY", 0)]
        if not prefix and local in BUS_WIRES:
            return [(BUS_WIRES[local], 0)]
        return [(p.function, p.index) for p in (m.pins if m else ()) if p.signal == local]

    def label(self, name: str) -> str:
        prefix, local = self._split(name)
        uses = []
        for function, index in self.functions(name):
            if function == "I2C_BUSY":
                uses.append("bus busy")
                continue
            if not prefix and local in BUS_WIRES:
                uses.append("I2C bus")
                continue
            if function == "SERVO_SIGNAL":
                pin = self._servo_pin(prefix, index)
                uses.append("pin %s" % pin if pin else "")
                continue
            kind = function.split("_", 1)
            if kind[0] == "MOTOR":
                uses.append("motor %d %s" % (index + 1, kind[1]))
            elif kind[0] == "SERVO":
                uses.append("servo %d" % index if kind[1:] == [] else "servo %s" % kind[1])
            else:
                uses.append(function.replace("_", " "))
        board = ("@%s " % prefix) if prefix else ""
        text = " / ".join(u for u in uses if u)
        return "%s%s%s" % (board, local, "\n" + text if text else "")

    def _servo_pin(self, prefix: str, index: int) -> Optional[str]:
        m = self.maps.get(prefix)
        pins = m.pins_of("SERVO", index) if m else ()
        return pins[0].signal if pins else None

    def periodic(self, name: str) -> bool:
        """Whether a period and a duty mean something on this line (a servo,
        a PWM output, a pin nobody named: yes; a bus or a serial line: no)."""
        uses = [f for f, _ in self.functions(name)]
        return not uses or not all(f in _NOT_PERIODIC for f in uses)

    def rank(self, name: str) -> Optional[int]:
        """Where a changing signal goes among the default rows (None: not shown
        by default: an M32-D servoN, which is its pin, or a counter line)."""
        uses = self.functions(name)
        prefix, local = self._split(name)
        if uses and uses[0][0] == "SERVO_SIGNAL" and self._servo_pin(prefix, uses[0][1]):
            return None                      # the M32-D: its pin's row is the servo's
        if not uses:
            return None if local.startswith("cnt") else 5
        if all(f in _HIDDEN for f, _ in uses):
            return None
        if self.bus_wires and local not in BUS_WIRES and \
                all(f in BUS_WIRES.values() for f, _ in uses):
            return None                      # a TWI pin: the rows sda and scl show its line
        return min(_RANK.get(f, 5) for f, _ in uses)


_MCU_PORTS = {"atmega32": "ABCD", "atmega128": "ABCDEFG"}


def _guess(names: Sequence[str]):
    """The board whose MCU has the ports the signals' pins show (the
    simulator lists every port pin; the ATmega128 has E, F and G)."""
    ports = {local[0] for local in (n.rpartition("/")[2] for n in names)
             if re.fullmatch(r"[A-G][0-7]", local)}
    for b in boardmap.BOARDS:
        m = boardmap.load(b)
        if set(_MCU_PORTS.get(m.mcu, "")) == ports:
            return m
    return None


def select(namer: Namer, names: Sequence[str], changing: Sequence[str],
           patterns: Optional[Sequence[str]]) -> Tuple[List[str], int]:
    """The rows to draw: the --signals patterns in their order (each must
    match), else the changing signals by rank; and how many more changed."""
    if patterns:
        chosen: List[str] = []
        for pat in patterns:
            # names are case-insensitive, as the simulator takes them
            hits = [n for n in names if fnmatch.fnmatchcase(n.lower(), pat.lower())]
            if not hits:
                raise UsageError("no signal %r (signals: %s)" % (pat, _some(names)))
            chosen += [h for h in hits if h not in chosen]
        return chosen, 0
    ranked = sorted((r, i, n) for i, n in enumerate(names) if n in changing
                    for r in [namer.rank(n)] if r is not None)
    rows = [n for _, _, n in ranked]
    return rows[:MAX_DEFAULT_ROWS], max(0, len(rows) - MAX_DEFAULT_ROWS)


def _some(names: Sequence[str], n: int = 12) -> str:
    return " ".join(names[:n]) + (" ..." if len(names) > n else "")


def _cycles(us: float, f_cpu: int) -> int:
    return int(round(us * f_cpu / 1e6))


def _windows(trace: vcd.Trace, start: int, end: int) -> Dict[str, waves.Wave]:
    """Every signal of the trace between start and end."""
    return {n: waves.window(n, trace.initial[n], trace.edges(n), start, end)
            for n in trace.names()}


Waves = Dict[str, waves.Wave]


def _from_file(args) -> Tuple[Waves, Waves, List[str], Namer, int, str]:
    """The window's waves, the whole file's (to decode), names, namer,
    clock and the title."""
    try:
        trace = vcd.load(args.trace)
    except OSError as exc:
        raise UsageError("cannot read %s: %s" % (args.trace, exc.strerror)) from None
    except vcd.VcdError as exc:
        raise UsageError(str(exc)) from None
    f = trace.f_cpu
    start = _cycles(args.start, f) if args.start is not None else 0
    end = _cycles(args.stop, f) if args.stop is not None else max(trace.end + 1, start + 1)
    if end <= start:
        raise UsageError("--to must be after --from")
    names = trace.names()
    whole = _windows(trace, 0, max(trace.end + 1, end))
    found = {n: waves.clip(w, start, end) for n, w in whole.items()}
    boards = trace.board_of()
    if args.board:
        boards[""] = args.board
    return found, whole, names, Namer(names, boards), f, os.path.basename(args.trace)


def _run_commands(port: str, args) -> None:
    """The --do commands, each as `orfa --port PORT COMMAND` (args.run: the
    command's main, handed down by add_parsers)."""
    for line in args.do or ():
        argv = ["--port", port, "--baud", str(args.baud)] + shlex.split(line)
        try:
            rc = args.run(argv)
        except SystemExit as exc:            # argparse's usage error, already told
            rc = exc.code if isinstance(exc.code, int) else 2
        if rc:
            raise UsageError("--do %r failed (exit %d)" % (line, rc))


RING = 1024                      # the simulator keeps at least the last 1024 edges of a signal
CHUNK_US = 1000                  # read them every simulated millisecond


def _record(ctl: SimControl, f_cpu: int, args) -> Tuple[Dict[str, waves.Wave], List[str], int]:
    """From now (after the --do commands), let --for of simulated time pass a
    millisecond at a time and take every signal's edges as they come, so
    the simulator's ring of the last 1024 edges holds them until they are
    read. The board runs on while this program reads, so a fast signal (a
    motor's PWM) can lose edges when the program is held up: it says which."""
    names = ctl.signals()
    first = ctl.requests(["time"] + ["level %s" % n for n in names])     # one cycle
    zero = since = int(first[0])
    levels = dict(zip(names, (int(r) for r in first[1:])))
    edges: Dict[str, List[Tuple[int, int]]] = {n: [] for n in names}
    end = zero + _cycles(args.span, f_cpu)
    lost = []
    while since < end:
        # one batch: the edges are read at the cycle the wait ends
        replies = ctl.requests(["wait %d" % min(_cycles(CHUNK_US, f_cpu), end - since)]
                               + ["edges %s %d" % (n, since) for n in names])
        now = int(replies[0])
        for n, reply in zip(names, replies[1:]):
            got = parse_edges(reply)
            if len(got) >= RING and n not in lost:
                lost.append(n)
            edges[n] += [e for e in got if e[0] < now]
        since = now
    if lost:
        print("orfa: plot: edges of %s were dropped before they could be read (the"
              " simulator keeps %d a signal); plot those from a VCD (orfa sim --vcd)"
              % (" ".join(lost), RING), file=sys.stderr)
    found = {n: waves.window(n, levels[n], edges[n], zero, since) for n in names}
    return found, names, zero


def _from_sim(args) -> Tuple[Dict[str, waves.Wave], List[str], Namer, int, str, int]:
    if args.trace:
        raise UsageError("give a VCD file or --sim/--control, not both")
    if args.sim is not None and args.control is not None:
        raise UsageError("give --sim (a board of its own) or --control (a running one),"
                         " not both")
    if args.sim is not None:
        # a board of our own: its VCD has every edge, however far the
        # simulator runs ahead of this program while it reads
        try:
            sim = sim_board(args.sim, args, trace=False, control=True, vcd=True).start()
        except (SimError, ValueError) as exc:
            raise UsageError(str(exc)) from None
        try:
            if args.autobaud:          # the BAUD=auto build finds --baud once, before the commands
                sim.gateway(args.baud, autobaud=True).close()
            t0 = sim.control.time()
            _run_commands(sim.port, args)
            zero = sim.control.time()
            t1 = sim.control.wait(_cycles(args.span, boardmap.load(args.sim).f_cpu))
            sim.stop(keep_dir=True)
            trace = vcd.load(str(sim.vcd_path))
        finally:
            sim.stop()
        names = trace.names()
        found = _windows(trace, t0, t1)
        return (found, names, Namer(names, trace.board_of()), trace.f_cpu,
                "simulated %s" % args.sim, zero)
    port = args.port or env_port()
    if args.do and not port:
        raise UsageError("--do with --control needs the board's --port (orfa sim prints it)")
    try:
        ctl = SimControl(args.control, connect_timeout=2.0)
    except (OSError, SimControlError) as exc:
        raise UsageError("cannot connect to %s: %s" % (args.control, exc)) from None
    with ctl:
        names = ctl.signals()
        namer = Namer(names, {"": args.board} if args.board else None)
        main_map = namer.maps.get("") or boardmap.load("m32d")
        _run_commands(port, args)
        found, names, zero = _record(ctl, main_map.f_cpu, args)
    return found, names, namer, main_map.f_cpu, "simulator at %s" % args.control, zero


def _narrow(found: Dict[str, waves.Wave], args, f_cpu: int, zero: int
            ) -> Dict[str, waves.Wave]:
    """Live: --from/--to count from the end of the --do commands (the start
    of --for); the recording's whole window without them."""
    if args.start is None and args.stop is None:
        return found
    out = {}
    for n, w in found.items():
        start = zero + _cycles(args.start, f_cpu) if args.start is not None else w.start
        end = zero + _cycles(args.stop, f_cpu) if args.stop is not None else w.end
        if end <= start:
            raise UsageError("--to must be after --from")
        out[n] = waves.clip(w, start, end)
    return out


SERVO_SHOWN_US = 100      # a servo channel pulsing shorter than this is not driven


def _idle_servo(namer: Namer, name: str, wave: waves.Wave, f_cpu: int) -> bool:
    """An M128-S servo channel that nobody drives: its CD4017 passes through
    it each frame, a pulse of a few microseconds (the default rows skip it)."""
    uses = namer.functions(name)
    if not uses or uses[0][0] != "SERVO_SIGNAL":
        return False
    return all(end - begin < _cycles(SERVO_SHOWN_US, f_cpu) for begin, end in waves.pulses(wave, 1))


#: The least margin around the activity when a window is trimmed to it.
TRIM_PAD_US = 50


def _activity(found: Dict[str, waves.Wave], names: Sequence[str], f_cpu: int
              ) -> Optional[Tuple[int, int]]:
    """The window around the activity of `names`: from a little before the
    first pulse of a row to a little after the last one. A lone edge (a pin
    the firmware sets at power-up, seconds before the servo moves) counts
    only when no row pulses. None: nothing moved."""
    # a row's pulses at its polarity: a UART line's bytes, not the long
    # "high pulse" from its power-up rise to the first byte
    times = [c for n in names for pulse in waves.pulses(found[n]) for c in pulse]
    if not times:
        times = [c for n in names for c, _ in found[n].edges]
    if not times:
        return None
    w0 = found[names[0]]
    pad = max((max(times) - min(times)) // 20, _cycles(TRIM_PAD_US, f_cpu))
    return max(w0.start, min(times) - pad), min(w0.end, max(times) + pad + 1)


def _frames_whole(window: Tuple[int, int], frames: Dict[str, List[decode.Frame]],
                  w0: waves.Wave) -> Tuple[int, int]:
    """The window widened to hold whole every decoded frame it cuts (a
    serial byte's stop bit after the line's last edge), within w0's."""
    start, end = window
    for f in (f for fs in frames.values() for f in fs):
        if f.start < start < f.end:
            start = f.start
        if f.start < end < f.end:
            end = f.end + 1
    return max(w0.start, start), min(w0.end, end)


def _clip_all(found: Dict[str, waves.Wave], window: Tuple[int, int]) -> Dict[str, waves.Wave]:
    return {n: waves.clip(w, *window) for n, w in found.items()}


def decoded(namer: Namer, whole: Waves, chosen: Sequence[str], f_cpu: int, baud: int
            ) -> Dict[str, List[decode.Frame]]:
    """What orfa.decode reads on the chosen rows, from their whole waves (a
    frame the window cuts is read right): a board's serial lines (UART_RX,
    UART_TX) at BAUD, and on the `sda` row the I2C bus when the capture has
    both `sda` and `scl`."""
    out = {}
    for n in chosen:
        uses = {f for f, _ in namer.functions(n)}
        if uses & {"UART_RX", "UART_TX"}:
            out[n] = decode.uart(whole[n], f_cpu / baud)
        elif n == "sda" and "scl" in whole:
            out[n] = decode.i2c(whole["sda"], whole["scl"])
    return out


def cmd_plot(args) -> int:
    """draw waveforms from a VCD or a live simulated board

    Draw servo pulses, motor PWM, chip selects and bus activity as a PNG
    (matplotlib), the time axis counted from the window's start (without
    --from/--to: trimmed to where the rows change) and the measured widths
    written on it. From a VCD file (orfa sim --vcd FILE), or live: --sim
    BOARD starts a board, runs the --do commands and records --for of
    simulated time; --control PATH does the same on a running `orfa sim
    --control PATH`. Prints one line per row: what it measured.

    examples: orfa plot board.vcd --signals 'servo*' --from 0 --to 40ms -o
    servo.png; orfa plot --sim m32d --do 'servo 3 1500' -o servo.png
    """
    try:
        drawing.require()                   # before a board starts and commands run
    except drawing.PlotUnavailable as exc:
        raise UsageError(str(exc)) from None
    live = args.sim is not None or args.control is not None
    if not live and not args.trace:
        raise UsageError("give a VCD file (orfa sim --vcd FILE) or --sim BOARD or --control PATH")
    if args.do and not live:
        raise UsageError("--do runs commands on a live board: give --sim or --control")
    if live:
        whole, names, namer, f_cpu, source, zero = _from_sim(args)
        found = _narrow(whole, args, f_cpu, zero)
    else:
        found, whole, names, namer, f_cpu, source = _from_file(args)
    patterns = [p for item in (args.signals or ()) for p in item.split(",") if p]

    def changing():
        return [n for n in names
                if found[n].edges and not _idle_servo(namer, n, found[n], f_cpu)]

    frames: Dict[str, List[decode.Frame]] = {}

    def frames_of(rows):
        """decoded() of ROWS, each row read once: the window below is
        widened by the frames, and the rows chosen again in it are drawn
        with theirs."""
        frames.update(decoded(namer, whole, [n for n in rows if n not in frames], f_cpu,
                              args.baud))
        return {n: frames[n] for n in rows if n in frames}

    chosen, more = select(namer, names, changing(), patterns)
    if chosen and args.start is None and args.stop is None:
        # no window asked for: the one where the rows' activity is, and
        # the default rows those that change in it
        window = _activity(found, chosen, f_cpu)
        if window is not None:
            window = _frames_whole(window, frames_of(chosen), found[chosen[0]])
            found = _clip_all(found, window)
            if not patterns:
                chosen, more = select(namer, names, changing(), patterns)
    if not chosen:
        # nothing moved: the servo rows, flat, rather than an empty picture
        chosen = [n for n in names if namer.rank(n) == 0][:4] or names[:4]
    shown = frames_of(chosen)
    rows = [drawing.Row(found[n], namer.label(n), namer.periodic(n), shown.get(n, ()))
            for n in chosen]
    try:
        notes = drawing.render(rows, f_cpu, args.output, title=source)
    except drawing.PlotUnavailable as exc:
        raise UsageError(str(exc)) from None
    except (OSError, ValueError) as exc:
        raise UsageError("cannot write %s: %s" % (args.output, exc)) from None
    for note in notes:
        if note.kind == "summary" or args.verbose:
            print("%-10s %s" % (note.signal, note.text))
    if more:
        print("(%d more signals changed; choose with --signals)" % more)
    return 0


def add_parsers(sub, common, run: Callable[[List[str]], int]) -> None:
    """`orfa plot`; `run(argv)` runs an orfa command line (its --do)."""
    cmd = command(sub, [common], cmd_plot)
    cmd.add_argument("trace", nargs="?", metavar="TRACE.vcd", help="the simulator's VCD file")
    cmd.add_argument("-o", "--output", required=True, metavar="OUT.png",
                     help="the picture to write (.png; .svg and .pdf work too)")
    cmd.add_argument("--signals", nargs="+", metavar="SIG",
                     help="the rows, in order: names as the simulator gives them (servo3,"
                          " D5, 10/servo3) or patterns ('servo*'), also comma separated;"
                          " default: the servo, motor, SPI, I2C and UART lines that change")
    cmd.add_argument("--from", dest="start", type=parse_time, metavar="T",
                     help="window start (1500, 1500us, 1.5ms, 0.02s); live: counted from"
                          " the end of the --do commands")
    cmd.add_argument("--to", dest="stop", type=parse_time, metavar="T", help="window end")
    cmd.add_argument("--for", dest="span", type=parse_time, default=float(DEFAULT_FOR_US),
                     metavar="T", help="live: simulated time to record (default 50ms)")
    cmd.add_argument("--do", action="append", metavar="'COMMAND ...'",
                     help="live: an orfa command run on the board before recording"
                          " ('servo 3 1500'), repeatable")
    cmd.add_argument("--control", metavar="PATH",
                     help="the control socket of a running `orfa sim --control PATH`")
    cmd.add_argument("--board", choices=boardmap.BOARDS,
                     help="the board the VCD or socket is of (default: told by its pins)")
    cmd.add_argument("-v", "--verbose", action="store_true",
                     help="also print every pulse's width")
    cmd.set_defaults(run=run)
