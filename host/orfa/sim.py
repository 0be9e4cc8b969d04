"""Simulated boards: start orfa-sim on a firmware ELF, talk to its port.

The simulator and the ELFs are found as orfa.locate says: ORFA_SIM and
ORFA_FIRMWARE, the installed package's copies, the repository's build/.

Every SimBoard gets its own temporary directory (link path, trace file, the
simulator's stdout/stderr), so any number run in parallel.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Dict, Iterable, List, NamedTuple, Optional, Sequence, Tuple, Union

from . import boardmap, locate
from .errors import SimError
from .gateway import Gateway
from .protocol import AUTOBAUD_PREAMBLE, DEFAULT_BAUD, F_CPU, autobaud_wait_s
from .simctl import SimControl

BOARDS = locate.BOARDS
REPO_ROOT = locate.REPO_ROOT
#: What to do about a missing build, as things were at import (build_hint()
#: says it as things are now).
BUILD_HINT = locate.build_hint()
build_hint = locate.build_hint
sim_path = locate.sim_path
firmware_path = locate.firmware_path
slave_firmware_path = locate.slave_firmware_path
missing_builds = locate.missing_builds


class TraceEvent(NamedTuple):
    """One trace line: `<cycle> <kind...> <fields...>` (docs/simulator.md)."""

    cycle: int
    kind: str           # "uart rx", "uart tx", "twi start", "twi addr", ..., "reset"
    fields: Tuple[str, ...]


def parse_trace_line(line: str) -> TraceEvent:
    words = line.split()
    if len(words) < 2 or not words[0].isdigit():
        raise ValueError("not a trace line: %r" % line)
    cycle = int(words[0])
    if words[1] in ("uart", "twi") and len(words) >= 3:
        return TraceEvent(cycle, words[1] + " " + words[2], tuple(words[3:]))
    return TraceEvent(cycle, words[1], tuple(words[2:]))


def parse_trace(text: str) -> List[TraceEvent]:
    return [parse_trace_line(line) for line in text.splitlines() if line.strip()]


#: A slave board on the simulated bus: (board, 8-bit address) or (board,
#: 8-bit address, ELF or None). Without an ELF, the slave build for that
#: address (slave_firmware_path: the installed package's, or build/'s), as
#: `orfa sim --slave BOARD:ADDR` and the pytest marker take it.
SlaveSpec = Union[Tuple[str, int], Tuple[str, int, Union[str, Path, None]]]


#: The trace's serial events and how their lines end: the gateway's replies
#: (`uart tx`) with CR LF, the PC's requests (`uart rx`) with LF.
_LINE_ENDS = {"uart tx": b"\r\n", "uart rx": b"\n"}


def sent_lines(events: Iterable[TraceEvent], since: int = 0, kind: str = "uart tx",
               last: bool = False) -> List[Tuple[int, str]]:
    """The lines on the gateway's serial line from cycle `since` on: with
    `kind` "uart tx" (the default) those the gateway sent, each ended by CR
    LF; with "uart rx" those it received, each ended by LF. As (the cycle
    of the line's first byte, or with `last` of its last, the line without
    its end); bytes after the last end are no line yet."""
    if kind not in _LINE_ENDS:
        raise ValueError("kind %r: one of %s" % (kind, ", ".join(map(repr, _LINE_ENDS))))
    end = _LINE_ENDS[kind]
    out, cur, first = [], bytearray(), 0
    for e in events:
        if e.kind != kind or e.cycle < since:
            continue
        if not cur:
            first = e.cycle
        cur.append(int(e.fields[0], 16))
        if cur.endswith(end):
            out.append((e.cycle if last else first,
                        bytes(cur[:-len(end)]).decode("ascii", "replace")))
            cur = bytearray()
    return out


def slave_spec(spec) -> Tuple[str, int, Union[str, Path, None]]:
    """(board, addr) or (board, addr, elf) -> (board, addr, elf or None);
    anything else is a ValueError that says what a slave is."""
    if not isinstance(spec, (tuple, list)) or len(spec) not in (2, 3) \
            or isinstance(spec[1], bool) or not isinstance(spec[1], int):
        raise ValueError("slave %r: (board, addr) or (board, addr, elf), e.g. (\"m128s\", 0x10)"
                         % (spec,))
    board, addr = spec[0], spec[1]
    if board not in BOARDS:
        raise ValueError("slave board %r: one of %s" % (board, ", ".join(BOARDS)))
    if not boardmap.address_ok(addr):
        raise ValueError("slave address %s: an 8-bit address, %s"
                         % ("0x%02X" % addr if addr >= 0 else addr, boardmap.ADDRESS_TEXT))
    return (board, addr, spec[2] if len(spec) == 3 else None)


def slave_option(spec: SlaveSpec) -> str:
    """The simulator's `--slave BOARD:ADDR:ELF` value of a SlaveSpec."""
    board, addr, elf = slave_spec(spec)
    path = Path(elf) if elf else slave_firmware_path(board, addr)
    return "%s:0x%02X:%s" % (board, addr, path)


#: A part on the I2C bus: (kind, 8-bit address) or (kind, address, options).
PartSpec = Union[Tuple[str, int], Tuple[str, int, str]]


def part_option(spec: PartSpec) -> str:
    """("bmp280", 0xEC) -> "bmp280@0xEC"; ("24lc32", 0xA8, "wp") -> "24lc32@0xA8:wp"."""
    if isinstance(spec, str) or not 2 <= len(spec) <= 3:
        raise ValueError("a part is (KIND, ADDR) or (KIND, ADDR, OPTIONS), not %r" % (spec,))
    kind, addr = spec[0], spec[1]
    opts = spec[2] if len(spec) == 3 else ""
    if not isinstance(addr, int) or not 0 <= addr <= 0xFF:
        raise ValueError("part %r: ADDR must be an 8-bit bus address (0xEC)" % (spec,))
    return "%s@0x%02X%s" % (kind, addr, ":" + opts if opts else "")


_part_kinds: Dict[str, Tuple[str, ...]] = {}


def part_kinds() -> Tuple[str, ...]:
    """The kinds of I2C parts the simulator makes (`orfa-sim --help` lists
    them); () when there is no simulator to ask."""
    path = str(sim_path())
    if path not in _part_kinds:
        try:
            text = subprocess.run([path, "--help"], stdout=subprocess.DEVNULL,
                                  stderr=subprocess.PIPE, timeout=10,
                                  universal_newlines=True).stderr
        except (OSError, subprocess.SubprocessError):
            return ()
        section = text.partition("Parts on the I2C bus")[2].partition("Parts on a board")[0]
        _part_kinds[path] = tuple(line.split()[0].split("[")[0]
                                  for line in section.splitlines()[1:] if line.strip())
    return _part_kinds[path]


def _die_with(parent: int):
    """For the simulator's child process (Linux): SIGTERM it when the thread
    that started it dies, killed or crashed, so no simulator is left running
    behind a test or a console that was killed (simulators are started from
    the main thread). If the parent is already gone, do not start at all."""
    def preexec() -> None:
        try:
            import ctypes
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGTERM)      # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            return
        if os.getppid() != parent:
            os._exit(1)
    return preexec


class SimBoard:
    """A simulated ORFA board running as a child process; a context manager.

    `.port` is the link to the board's serial port (open it with pyserial or
    Gateway); `.trace_path` the trace file (if trace=True). With control=True
    `.control` is a SimControl on the board's control socket; vcd=True writes
    `.vcd_path`; spi=["eeprom25@B4", "mcp3008@B3:mode=0"], adc={0: 1000},
    avcc/aref (mV) set the board's SPI devices and analog inputs; srf08=[0xE0]
    puts SRF08 range finders on the I2C bus (their `srf08` control request
    sets what they sense). parts=[("bmp280", 0xEC), ("24lc32", 0xA8, "wp")]
    puts parts of any kind on the I2C bus (`--part KIND@0xADDR[:OPTIONS]`;
    `orfa-sim --help` lists the kinds); control.sense() sets what they sense.

    slaves=[("m128s", 0x10), ("m32d", 0x12, elf_path), ...] puts further
    boards, each running its own firmware (without an ELF, or None: the
    slave build for that address, slave_firmware_path), on the
    same I2C bus as I2C slaves: a robot. The control socket reaches them as
    `10/servo3` (signals) and `@10` (other requests); see docs/simulator.md.
    """

    def __init__(self, board: str = "m32d", eeproms: Sequence[int] = (),
                 trace: bool = True, firmware: Union[str, Path, None] = None,
                 start_timeout: float = 15.0, extra_args: Sequence[str] = (),
                 control: bool = False, vcd: bool = False, spi: Sequence[str] = (),
                 adc: Optional[Dict[int, int]] = None, avcc: Optional[int] = None,
                 aref: Optional[int] = None, srf08: Sequence[int] = (),
                 slaves: Sequence[SlaveSpec] = (), parts: Sequence[PartSpec] = ()):
        if board not in BOARDS:
            raise ValueError("board must be one of %s" % (BOARDS,))
        self.board = board
        self.eeproms = tuple(eeproms)
        self.srf08 = tuple(srf08)
        self.part_options = [part_option(spec) for spec in parts]
        self.firmware = Path(firmware) if firmware else firmware_path(board)
        self.start_timeout = start_timeout
        self.extra_args = tuple(extra_args)
        self.want_trace = trace
        self.want_control = control
        self.want_vcd = vcd
        self.spi = tuple(spi)
        self.adc = dict(adc or {})
        self.avcc = avcc
        self.aref = aref
        self.slaves = tuple(slave_spec(spec) for spec in slaves)
        self.slave_options = [slave_option(spec) for spec in self.slaves]
        self.control_path: Optional[Path] = None
        self.vcd_path: Optional[Path] = None
        self._control: Optional[SimControl] = None
        self.dir: Optional[Path] = None
        self.port = ""
        self.trace_path: Optional[Path] = None
        self.proc: Optional[subprocess.Popen] = None
        self.banner = ""
        self.final_stderr = ""

    # --- lifetime -------------------------------------------------------------
    def command(self) -> List[str]:
        options = ([("--eeprom", "0x%02X" % addr) for addr in self.eeproms]
                   + [("--srf08", "0x%02X" % addr) for addr in self.srf08]
                   + [("--part", opt) for opt in self.part_options]
                   + [("--trace", self.trace_path), ("--control", self.control_path),
                      ("--vcd", self.vcd_path)]
                   + [("--spi", spec) for spec in self.spi]
                   + [("--adc", "%d=%d" % item) for item in sorted(self.adc.items())]
                   + [("--avcc", self.avcc), ("--aref", self.aref)]
                   + [("--slave", opt) for opt in self.slave_options])
        cmd = [str(sim_path()), "--board", self.board, "--link", self.port]
        for option, value in options:
            if value is not None:                  # None: an option not given
                cmd += [option, str(value)]
        return cmd + list(self.extra_args) + [str(self.firmware)]

    def start(self) -> "SimBoard":
        slave_elfs = [Path(opt.split(":", 2)[2]) for opt in self.slave_options]
        for path in [sim_path(), self.firmware] + slave_elfs:
            if not path.is_file():
                raise SimError("%s is missing: %s" % (path, build_hint()))
        self.dir = Path(tempfile.mkdtemp(prefix="orfa-sim-%s-" % self.board))
        self.port = str(self.dir / "tty")
        self.trace_path = self.dir / "trace.log" if self.want_trace else None
        self.control_path = self.dir / "control" if self.want_control else None
        self.vcd_path = self.dir / "board.vcd" if self.want_vcd else None
        self._stdout = open(self.dir / "stdout", "wb")
        self._stderr = open(self.dir / "stderr", "wb")
        try:
            self.proc = subprocess.Popen(self.command(), stdin=subprocess.DEVNULL,
                                         stdout=self._stdout, stderr=self._stderr,
                                         preexec_fn=_die_with(os.getpid()))
        except OSError as exc:          # not executable, not a program
            self._stdout.close()
            self._stderr.close()
            self.stop()
            raise SimError("cannot run %s: %s; %s" % (
                sim_path(), exc.strerror or exc, build_hint())) from None
        deadline = time.monotonic() + self.start_timeout
        while not os.path.exists(self.port):
            if self.proc.poll() is not None:
                msg = "orfa-sim exited with %d before its link appeared" % self.proc.returncode
                self._fail(msg, refused=self.proc.returncode == 2)
            if time.monotonic() > deadline:
                self._fail("orfa-sim made no link within %.0f s" % self.start_timeout)
            time.sleep(0.01)
        # the simulator prints its line just after it makes the link
        self.banner = self._read("stdout")
        while not self.banner.endswith("\n") and self.proc.poll() is None \
                and time.monotonic() < deadline:
            time.sleep(0.002)
            self.banner = self._read("stdout")
        return self

    def _read(self, name: str) -> str:
        try:
            return (self.dir / name).read_text(errors="replace")
        except OSError:
            return ""

    def _fail(self, msg: str, refused: bool = False) -> None:
        cmd = " ".join(self.command())
        stderr = self._read("stderr")
        self.stop()
        err = SimError("%s\n  command: %s\n  stderr: %s" % (msg, cmd, stderr.strip() or "(empty)"))
        if refused and stderr.strip() and "\n" not in stderr.strip():
            err.refused = stderr.strip()
        raise err

    def stop(self, keep_dir: bool = False) -> Optional[int]:
        """SIGTERM the simulator, wait for it; returns its exit status."""
        status = None
        if self._control is not None:
            self._control.close()
            self._control = None
        if self.proc is not None:
            if self.proc.poll() is None:
                self.proc.send_signal(signal.SIGTERM)
                try:
                    self.proc.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    self.proc.kill()
                    self.proc.wait()
            status = self.proc.returncode
            self.proc = None
            self._stdout.close()
            self._stderr.close()
            self.final_stderr = self._read("stderr")
        if self.dir is not None and not keep_dir:
            shutil.rmtree(self.dir, ignore_errors=True)
            self.dir = None
        return status

    def __enter__(self) -> "SimBoard":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        return self.proc is not None and self.proc.poll() is None

    @property
    def control(self) -> SimControl:
        """The control socket's client (start the board with control=True)."""
        if self.control_path is None or self.proc is None:
            raise SimError("this board was started without control=True")
        if self._control is None:
            self._control = SimControl(str(self.control_path))
        return self._control

    def wait_s(self, seconds: float) -> int:
        """Let `seconds` of simulated time pass (control socket); the cycle
        reached."""
        return self.control.wait(int(math.ceil(seconds * F_CPU)))

    def gateway(self, baudrate: int = DEFAULT_BAUD, autobaud: bool = False,
                **kw) -> Gateway:
        """A Gateway on this board's port at `baudrate`; autobaud=True sends
        the BAUD=auto preamble and waits its quiet in simulated time (needs
        control=True; see preamble)."""
        gw = Gateway(self.port, baudrate=baudrate, **kw)
        if autobaud:
            try:
                self.preamble(gw.serial)
            except BaseException:
                gw.close()
                raise
        return gw

    def pc_write(self, port, data: bytes) -> int:
        """Write `data` to the PC's `port` (a pyserial port on self.port) and
        let simulated time pass until the simulator has taken all of it (the
        kernel hands it over in wall time; SimControl.wait_taken): what a
        test measures from the returned cycle on does not depend on the
        machine's load. Needs control=True."""
        before = self.control.line()["pty"]
        port.write(data)
        port.flush()
        return self.control.wait_taken(before + len(data))

    def preamble(self, port) -> int:
        """The BAUD=auto preamble at the port's rate, taken by the simulator
        (pc_write), then its quiet in simulated time; the cycle reached."""
        self.pc_write(port, AUTOBAUD_PREAMBLE)
        return self.wait_s(autobaud_wait_s(port.baudrate))

    def speed(self) -> Optional[float]:
        """After stop(): world cycles per wall second while running free, in
        MHz, from the simulator's exit line (each of the boards ran that many
        cycles); None when it printed none."""
        m = re.search(r"running free ([0-9.]+) simulated MHz", self.final_stderr)
        return float(m.group(1)) if m else None

    @property
    def stderr(self) -> str:
        return self._read("stderr") if self.dir else ""

    # --- trace ------------------------------------------------------------------
    def trace_text(self) -> str:
        if self.trace_path is None:
            raise SimError("this board was started without a trace")
        try:
            return self.trace_path.read_text()
        except FileNotFoundError:
            return ""

    def trace_mark(self) -> int:
        """A position in the trace; trace_events(since=mark) gives what follows."""
        return len(self.trace_text().encode())

    def stretches(self, since: int = 0) -> List[Tuple[int, int, int]]:
        """[(cycle, slave address, cycles)] of the `twi stretch` trace lines:
        a slave held SCL low and the master's next operation waited."""
        return [(e.cycle, int(e.fields[0], 16), int(e.fields[1]))
                for e in self.trace_events(since, ["twi stretch"])]

    def trace_events(self, since: int = 0, kinds: Optional[Iterable[str]] = None
                     ) -> List[TraceEvent]:
        """Parsed trace events after position `since`, optionally only some kinds.

        A kind matches by prefix: "twi" gives every bus event.
        """
        data = self.trace_text().encode()[since:]
        text = data.decode()
        cut = text.rfind("\n")
        events = parse_trace(text[:cut + 1])
        if kinds is not None:
            kinds = tuple(kinds)
            events = [e for e in events if e.kind.startswith(kinds)]
        return events


class SimRobot(SimBoard):
    """A gateway board and its slave boards on one simulated I2C bus.

    SimRobot("m32d", slaves=[("m128s", 0x10), ("m32d", 0x12)])
    is SimBoard with the gateway board first; every SimBoard option applies
    (to the gateway's board, and the control socket reaches every board).
    """

    def __init__(self, gateway: str = "m32d", slaves: Sequence[SlaveSpec] = (), **kw):
        super().__init__(gateway, slaves=slaves, **kw)
