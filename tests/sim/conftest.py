"""Simulated boards for the protocol suite.

One simulator per board and test module (module scope, for speed); every test
gets it through the `gw` fixture, which checks on entry that the line is idle
and on exit puts back what tests change (local address, clock), so no test
sees another's state. Each simulator has its own temp dir and link path.
"""

import contextlib
import math
import re
import time
from pathlib import Path

import pytest

from orfa import boardmap
from orfa import protocol as p
from orfa.gateway import Gateway
from orfa.locate import gateway_firmware
from orfa.sim import BOARDS, BUILD_HINT, SimBoard, missing_builds

ROOT = Path(__file__).resolve().parents[2]
EEPROM = 0xA0
EEPROM_WP = 0xA6         # write-protected 24C02: acknowledges its address and
                         # the word address, not the data bytes
#: Wall-clock seconds a reply may take (the simulator runs faster than real time).
REPLY_TIMEOUT = 5.0
#: The table of sensor readings (test_sensor_drivers.py: the value set, the
#: value a driver returned), printed at the end of the run.
SENSOR_READINGS = pytest.StashKey[list]()


def require_builds(boards=BOARDS):
    missing = missing_builds(boards)
    if missing:
        pytest.fail("missing %s: %s" % (", ".join(map(str, missing)), BUILD_HINT),
                    pytrace=False)


def build_gateway(board: str, baud) -> Path:
    """A gateway firmware for `board` at `baud` (a rate, or "auto"): the one
    `orfa --sim` runs at that rate (orfa.locate.gateway_firmware: the
    default build at 115200, else build/<board>-gate-<baud>/, made once per
    session); its ELF."""
    if (board, baud) not in _BUILT:
        try:
            _BUILT[(board, baud)] = gateway_firmware(board, baud)
        except ValueError as exc:
            pytest.fail(str(exc), pytrace=False)
    return _BUILT[(board, baud)]


_BUILT = {}


def board_sent(sim: SimBoard, since: int) -> bytes:
    """The bytes the board's firmware sent from cycle `since` on (the
    trace's `uart tx`): what it answered, decided in simulated time; a
    trace event is written before the simulator answers a later `wait`."""
    return bytes(int(e.fields[0], 16) for e in sim.trace_events(kinds=["uart tx"])
                 if e.cycle >= since)


def wait_quiet(ctl, port, cycles: int) -> None:
    """Let the board's time pass until it has sent nothing for two stretches
    of `cycles` in a row (what came read and dropped): the replies a flood
    beyond the flow rule left owed (thousands of `ERROR 04`) are out."""
    quiet = 0
    for _ in range(WAIT_QUIET_TURNS):
        ctl.wait(cycles)
        waiting = port.in_waiting
        port.read(waiting)
        quiet = 0 if waiting else quiet + 1
        if quiet == 2:
            return
    pytest.fail("the board still sends after %d stretches of %d cycles" % (WAIT_QUIET_TURNS, cycles),
                pytrace=False)


#: wait_quiet()'s bound: a board that never stops sending fails, not hangs
WAIT_QUIET_TURNS = 500


class Bench:
    """A running simulated board, the open serial port, and helpers."""

    def __init__(self, sim: SimBoard, gw: Gateway = None):
        self.sim = sim
        self.board = sim.board
        self.own_gw = gw is None
        self.gw = gw if gw is not None else Gateway(sim.port, timeout=REPLY_TIMEOUT)

    def close(self):
        if self.own_gw:
            self.gw.close()

    # --- raw bytes ------------------------------------------------------------
    def read_lines(self, count: int, timeout: float = REPLY_TIMEOUT) -> bytes:
        """Exactly `count` CR LF-ended lines, as received."""
        out = bytearray()
        deadline = time.monotonic() + timeout
        for _ in range(count):
            line = bytearray()
            while not line.endswith(b"\r\n"):
                if time.monotonic() > deadline:
                    raise AssertionError("timed out after %r (waiting for %d lines)"
                                         % (bytes(out + line), count))
                line += self.gw.serial.read_until(b"\r\n")
            out += line
        return bytes(out)

    def exchange(self, data: bytes, lines: int) -> bytes:
        """Send raw bytes, return the `lines` reply lines they get."""
        self.gw.send(data)
        return self.read_lines(lines)

    def ask(self, request, end: bytes = b"\n") -> bytes:
        """One request (str or bytes), its reply line exactly as received."""
        if isinstance(request, str):
            request = request.encode("ascii")
        return self.exchange(request + end, 1)

    def assert_silent(self):
        """Nothing more comes for what was sent. The board answers in order,
        so a `V` sent now must get the very next reply line: decided by the
        board's own order, not by waiting on the wall clock (a simulator of
        several boards runs slower than one)."""
        reply = self.exchange(b"V\n", 1)
        assert reply == b"V1.1\r\n", "unexpected bytes from the board: %r" % reply

    def settle(self):
        """End a line a test may have left open and skip every reply still
        coming: the replies up to the `V` sent last."""
        self.gw.send(b"\nV\n")
        for _ in range(300):
            if self.read_lines(1) == b"V1.1\r\n":
                return
        raise AssertionError("the board did not come back to its V")

    # --- trace ----------------------------------------------------------------
    def mark(self) -> int:
        return self.sim.trace_mark()

    def events(self, since: int, kinds=None):
        return self.sim.trace_events(since, kinds)

    def bus(self, since: int):
        """The bus events since `since`, as ("start",), ("addr", "A0", "ack"), ...
        (a slave's clock stretching, `twi stretch`, left out)."""
        return [(e.kind[4:],) + e.fields for e in self.events(since, ["twi"])
                if e.kind != "twi stretch"]

    # --- the local register map -------------------------------------------------
    def local_ok(self, request: str) -> bytes:
        """A request's reply text that must be a transaction reply."""
        reply = self.ask(request)
        assert reply.startswith(b"S") and reply.endswith(b"P\r\n"), (request, reply)
        return reply[:-2]

    def driver_count(self) -> int:
        reply = self.ask("S AA 00 00 S AB 01 P")
        assert reply[:6] == b"SWAASR" and reply[8:] == b"P\r\n", reply
        return int(reply[6:8], 16)

    def record(self, n: int) -> bytes:
        """Introspection record of driver n, read on its own."""
        reply = self.ask("S AA 00 %02X S AB 06 P" % n)
        assert reply[:6] == b"SWAASR" and reply[18:] == b"P\r\n", (n, reply)
        return bytes.fromhex(reply[6:18].decode())

    def status(self) -> int:
        reply = self.ask("S AA 01 S AB 01 P")
        assert reply[:5] == b"SWASR" and reply[7:] == b"P\r\n", reply
        return int(reply[5:7], 16)

    def eeprom_read(self, addr: int, count: int) -> bytes:
        (_, result) = self.gw.transaction([p.Write(EEPROM, bytes([addr])), p.Read(EEPROM, count)])
        return result.data

    def eeprom_write(self, addr: int, data: bytes) -> None:
        assert self.gw.write(EEPROM, bytes([addr]) + data) == 1 + len(data)

    def restore(self):
        """Put back what tests change; fails if the board does not answer.

        The leading LF ends any line a test left open (its reply, if any, is
        skipped); the three requests after it must then answer in order.
        """
        want = [b"LAA\r\n", b"C0063\r\n", b"V1.1\r\n"]
        self.gw.send(b"\nL AA\nC 00 64\nV\n")
        lines = []
        for _ in range(5):
            lines.append(self.read_lines(1))
            if lines[-3:] == want:
                break
        assert lines[-3:] == want, "the board did not come back: %r" % lines
        assert self.sim.running, self.sim.stderr


class ControlBench(Bench):
    """A Bench on a simulator with its control socket (control=True): request
    lines put on the serial line at chosen cycles, the bus events traced."""

    def __init__(self, sim: SimBoard):
        super().__init__(sim)
        self.ctl = sim.control

    def rx(self, cycle: int, line: str) -> int:
        """Put a request line on the serial line at `cycle`; its end cycle."""
        return self.ctl.rx(cycle, line.encode("ascii") + b"\n")

    def twi(self, since: int, kind: str):
        """(cycle, fields) of the bus events of one kind ("addr", "write")."""
        return [(e.cycle, e.fields) for e in self.events(since, ["twi " + kind])]


@contextlib.contextmanager
def running(sim: SimBoard, make_bench=Bench):
    """Start `sim`, give a bench on it (make_bench(sim)), and stop it after:
    the simulator must exit cleanly."""
    sim.start()
    b = make_bench(sim)
    try:
        yield b
    finally:
        b.close()
        status = sim.stop()
        assert status == 0, "orfa-sim exited with %r" % status
        # The watchdog never fires in normal use: no reset in the whole
        # run, unless the test made one on purpose (test_watchdog.py).
        if sim.want_trace and not getattr(sim, "expect_resets", False):
            resets = sim.trace_events(kinds=["reset"])
            assert resets == [], "the board reset: %r" % resets


def bench_running(board: str, make_bench=Bench, **sim_options):
    """The body of a module's fixture (`yield from`): a simulated BOARD
    (SimBoard's SIM_OPTIONS; trace=True, for the checks of `for_each_test`)
    built and started, its bench made by MAKE_BENCH, stopped after the
    module (`running`)."""
    require_builds([board])
    with running(SimBoard(board, **sim_options), make_bench) as b:
        yield b


def for_each_test(bench, prepare=None, tidy=None, settle=False):
    """The body of a test's fixture over a module's BENCH (`yield from`): the
    simulator alive, the serial input flushed, PREPARE(bench) run; after the
    test, with SETTLE the replies a test left coming skipped, TIDY(bench)
    putting back what the module changes, restore() the board's defaults;
    the MCU must not have reset meanwhile."""
    assert bench.sim.running, "the simulator died: %s" % bench.sim.stderr
    bench.gw.reset_input_buffer()
    mark = bench.mark()
    if prepare:
        prepare(bench)
    yield bench
    if settle:
        bench.settle()
    if tidy:
        tidy(bench)
    bench.restore()
    resets = bench.events(mark, ["reset"])
    assert resets == [], "the MCU reset during the test: %r" % resets


@pytest.fixture(scope="module", params=BOARDS)
def bench(request):
    # and a write-protected one that refuses data bytes (ERROR 07)
    yield from bench_running(request.param, eeproms=(EEPROM,), trace=True,
                             extra_args=("--eeprom", "0x%02X:wp" % EEPROM_WP))


@pytest.fixture
def board(bench):
    """The module's board, idle and in its default state."""
    yield from for_each_test(bench)


# --- driver suites (tests/sim/test_drv_*.py) ----------------------------------
#
# The driver tests look at the board's pins through the simulator's control
# socket (docs/simulator.md), so their simulators run with control=True. Each
# test module gets its own simulator per board (module scope) through the
# `drv_sim` fixture; the `drv` fixture gives it to a test and puts every
# driver back into its reset state afterwards (servos off, motors stopped, ADC
# off, SPI bus settings 02, GPIO lines inputs without pull-up, external drives
# released), so no test sees another's state.

F_CPU = boardmap.F_CPU
#: One servo frame: 20 ms.
SERVO_FRAME = F_CPU * 20 // 1000
#: docs/registers.md "Servos": widths within 1.1 us = 8 cycles of the command.
WIDTH_TOL = 8

def _layout(board: str) -> dict:
    """Registers and pins of a board with all its drivers, from its map
    (orfa.boardmap, generated from the firmware's C definitions)."""
    m = boardmap.load(board)
    servo_pins = sorted(m.pins_of("SERVO"), key=lambda pin: pin.index)
    fixed = {}
    for pin in m.pins:
        kind = pin.function.split("_")[0]
        if pin.function != "SERVO":          # a servo channel's pin is GPIO's when off
            fixed[pin.signal] = kind
    return {
        "gpio_ports": m.gpio_ports,
        "gpio_val": m.reg("gpio", "VALUE_" + m.gpio_ports[0]),
        "gpio_mode": m.reg("gpio", "MODE_" + m.gpio_ports[0]),
        "spi": m.reg("spi", "DATA"), "adc": m.reg("adc", "RC"),
        "motor": m.reg("motor", "PWM1") if m.has("motor") else None,
        "servo": m.reg("servo", "RS"), "sys": m.reg("sys", "RESET"),
        "servo_channels": m.servo_channels, "adc_port": m.adc_port,
        "spi_pins": {pin.function[4:]: pin.signal for pin in m.pins
                     if pin.function.startswith("SPI_")},
        # channel n's pin; the simulator's signal when counters drive them
        "servo_pins": ([pin.signal for pin in servo_pins] if servo_pins
                       else ["servo%d" % n for n in range(m.servo_channels)]),
        "fixed_scl": m.pins_of("TWI_SCL")[0].signal,
        # pins of functions that GPIO never has (UART, TWI, SPI, motors, counters)
        "fixed_pins": fixed,
    }


#: Registers and pins of each board (docs/board-<board>.md).
DRV_LAYOUT = {board: _layout(board) for board in boardmap.BOARDS}


def raw(value: float, per_unit: float, lo: int = -32768, hi: int = 32767) -> int:
    """A sensor register's code for VALUE at PER_UNIT LSB per unit: rounded
    to nearest (ties upward), saturated, as the simulated parts report it
    (the datasheets' conversion)."""
    return max(lo, min(hi, math.floor(value * per_unit + 0.5)))


def us_to_cycles(us: float) -> float:
    return us * F_CPU / 1e6


class DrvBench(Bench):
    """A Bench with the simulator's control socket and register helpers,
    aimed at one board's drivers: the gateway's own (local address AA), or
    a slave board's at its bus address (`addr`), through the gateway. The
    helpers and `ctl` (pins, analog inputs, SPI log) then reach that board,
    so a driver test runs unchanged against either."""

    def __init__(self, sim: SimBoard, board: str = None, addr: int = None,
                 gw: Gateway = None):
        super().__init__(sim, gw)
        self.board = board or sim.board
        self.slave = addr is not None
        self.addr = addr if self.slave else 0xAA
        #: the write and read address as the protocol writes them: "AA", "AB"
        self.wa = "%02X" % self.addr
        self.ra = "%02X" % (self.addr | 1)
        self.ctl = sim.control.slave(addr) if self.slave else sim.control
        self.lay = DRV_LAYOUT[self.board]
        self.driven = set()

    # --- registers ------------------------------------------------------------
    def req(self, text: str) -> str:
        """A request written for the local address, aimed at this board:
        "S AA 02 S AB 01 P" -> "S 12 02 S 13 01 P" on the slave at 0x12."""
        text = re.sub(r"S(\s*)AA", lambda m: "S" + m.group(1) + self.wa, text)
        return re.sub(r"S(\s*)AB", lambda m: "S" + m.group(1) + self.ra, text)

    def driver_count(self) -> int:
        reply = self.ask(self.req("S AA 00 00 S AB 01 P"))
        assert reply[:6] == b"SWAASR" and reply[8:] == b"P\r\n", reply
        return int(reply[6:8], 16)

    def record(self, n: int) -> bytes:
        reply = self.ask(self.req("S AA 00 %02X S AB 06 P" % n))
        assert reply[:6] == b"SWAASR" and reply[18:] == b"P\r\n", (n, reply)
        return bytes.fromhex(reply[6:18].decode())

    def status(self) -> int:
        reply = self.ask(self.req("S AA 01 S AB 01 P"))
        assert reply[:5] == b"SWASR" and reply[7:] == b"P\r\n", reply
        return int(reply[5:7], 16)

    def wr(self, reg: int, data: bytes = b"") -> None:
        """A register write the driver must accept."""
        data = bytes(data)
        req = "S%s%02X%sP" % (self.wa, reg, data.hex().upper())
        reply = self.ask(req)
        assert reply == b"SW" + b"A" * (1 + len(data)) + b"P\r\n", (req, reply)
        if self.slave:
            # a slave acknowledges before its driver decides: ask it
            assert self.status() == 0, req

    def wr_refused(self, reg: int, data: bytes, status: int) -> None:
        """A register write the driver must reject with `status`: the gateway
        replies ERROR 07 for its own drivers. A slave acknowledges a byte
        before it is seen (docs/registers.md, "On a slave board"): a byte that
        makes the write invalid is refused with the byte after it (ERROR 07), and one that
        is the last, or a write found wrong only when the frame ends, is
        acknowledged in full (SW..P); the status register tells either way
        (tests/sim/test_robot.py pins down which is which)."""
        data = bytes(data)
        req = "S%s%02X%sP" % (self.wa, reg, data.hex().upper())
        reply = self.ask(req)
        if self.slave:
            assert reply in (b"ERROR 07\r\n", b"SW" + b"A" * (1 + len(data)) + b"P\r\n"), \
                (req, reply)
        else:
            assert reply == b"ERROR 07\r\n", (req, reply)
        assert self.status() == status, req

    def unreadable(self, reg: int, count: int = 1) -> None:
        """A register that cannot be read: the gateway refuses the read
        (ERROR 06); a slave acknowledges its read address anyway and sends
        FF (docs/registers.md, "On a slave board"). The status register says 05
        either way."""
        reply = self.ask(self.req("S AA %02X S AB %02X P" % (reg, count)))
        if self.slave:
            assert reply == b"SWASR" + b"FF" * count + b"P\r\n", reply
        else:
            assert reply == b"ERROR 06\r\n", reply
        assert self.status() == 0x05

    def rd(self, reg: int, count: int) -> bytes:
        """Select `reg`, read `count` bytes; the reply must be a good one."""
        req = "S %s %02X S %s %02X P" % (self.wa, reg, self.ra, count)
        reply = self.ask(req)
        assert reply[:5] == b"SWASR" and reply[-3:] == b"P\r\n", (req, reply)
        data = bytes.fromhex(reply[5:-3].decode())
        assert len(data) == count, (req, reply)
        return data

    # --- the pins ---------------------------------------------------------------
    def pin(self, name: str):
        return self.ctl.pin(name)

    def read_levels(self, port: str) -> int:
        """What the board's GPIO value register reads for `port`: its pin
        levels, except that a slave board reads its own SCL low, since it
        holds SCL (clock stretching) while it answers the read. The TWI
        pins show the bus's wired-AND lines (docs/simulator.md)."""
        value = sum(self.pin("%s%d" % (port, l))[0] << l for l in range(8))
        scl = self.lay["fixed_scl"]
        if self.slave and scl[0] == port:
            value &= ~(1 << int(scl[1]))
        return value

    def drive(self, name: str, value) -> None:
        self.ctl.drive(name, value)
        if value is None or value == "z":
            self.driven.discard(name)
        else:
            self.driven.add(name)

    def now(self) -> int:
        return self.ctl.time()

    def wait(self, cycles: int) -> int:
        return self.ctl.wait(cycles)

    def edges(self, sig: str, since: int):
        return self.ctl.edges(sig, since)

    def measure(self, sig: str, since: int, n: int = 50):
        return self.ctl.measure(sig, n, since)

    def highs(self, sig: str, since: int, until: int = None):
        """[(rise, high cycles, period to the next rise or None)] of complete
        pulses whose rising edge is at or after `since` (and falls <= until)."""
        edges = self.edges(sig, since)
        out = []
        for i, (cycle, level) in enumerate(edges):
            if level != 1 or i + 1 >= len(edges):
                continue
            fall = edges[i + 1][0]
            if until is not None and fall > until:
                continue
            nxt = [c for c, l in edges[i + 1:] if l == 1]
            out.append((cycle, fall - cycle, (nxt[0] - cycle) if nxt else None))
        return out

    # --- state --------------------------------------------------------------------
    def servos_off(self) -> None:
        lay = self.lay
        chans = lay["servo_channels"]
        for first in range(0, chans, 16):
            self.wr(lay["servo"] + 1, b"".join(bytes([ch, 0, 0]) for ch in range(first, first + 16)))
        self.wr(lay["servo"] + 1, b"\x00")

    def drv_restore(self) -> None:
        """Every driver back to its reset state (SPI chip selects aside)."""
        lay = self.lay
        self.settle()                 # end a line a test left open
        for name in sorted(self.driven):
            self.ctl.drive(name, None)
        self.driven.clear()
        self.servos_off()
        if lay["motor"] is not None:
            self.wr(lay["motor"], b"\x00\x00\x00\x00")
        self.wr(lay["adc"], b"\x00\x00")
        self.wr(lay["spi"] + 1, b"\xff\x00\x02")
        for i, _ in enumerate(lay["gpio_ports"]):
            self.wr(lay["gpio_mode"] + i, b"\x00\xff")
            self.wr(lay["gpio_val"] + i, b"\x00\xff")


#: Where the driver suites run: each board's own drivers behind its gateway
#: (the local address AA), and each board as a slave of an M32-D gateway at
#: its bus address ("m128s@10": the M128-S slave at 0x10). The slaves are the
#: test robot's (Makefile `robot`: build/robot/<board>-<addr>/orfa.elf).
SLAVE_ADDR = {"m128s": 0x10, "m32d": 0x12}
DRV_TARGETS = list(BOARDS) + ["%s@%02X" % (b, SLAVE_ADDR[b]) for b in BOARDS]
GATEWAY_OF_SLAVES = "m32d"


def target(name: str):
    """"m128s@10" -> ("m128s", 0x10); "m32d" -> ("m32d", None)."""
    board, _, addr = name.partition("@")
    return board, (int(addr, 16) if addr else None)


def slave_firmware(board: str, addr: int) -> Path:
    return ROOT / "build" / "robot" / ("%s-0x%02X" % (board, addr)) / "orfa.elf"


def require_slave(board: str, addr: int) -> Path:
    elf = slave_firmware(board, addr)
    if not elf.is_file():
        pytest.fail("missing %s: build the test robot with `make robot`" % elf, pytrace=False)
    return elf


#: The robot of the bus-fault tests (test_abandoned.py,
#: test_bus_faults_midbyte.py): a gateway and two slave boards of the test
#: robot, an M128-S at 0x10 and an M32-D at 0x12.
M128S, M32D = 0x10, 0x12
SLAVES = {M128S: "m128s", M32D: "m32d"}
OK, DROPPED = 0x00, 0x09          # a slave's status: a write applied, one dropped


def sp(addr):
    """The servo widths' register (SP) of slave ADDR."""
    return DRV_LAYOUT[SLAVES[addr]]["servo"] + 1


def mode(addr):
    """The first GPIO port's mode register of slave ADDR."""
    return DRV_LAYOUT[SLAVES[addr]]["gpio_mode"]


def clear(b, addr):
    """Every servo of the slave off, its first GPIO port inputs, status OK."""
    a = addr
    offs = "".join("%02X0000" % ch for ch in range(16))
    assert b.ask("S %02X %02X %s P" % (a, sp(a), offs)) == b"SW" + b"A" * 49 + b"P\r\n"
    assert b.ask("S %02X %02X 00 P" % (a, mode(a))) == b"SWAAP\r\n"
    assert status(b, a) == OK


def status(b, addr):
    """Slave ADDR's status register (OK, DROPPED: docs/registers.md)."""
    reply = b.ask("S %02X 01 S %02X 01 P" % (addr, addr | 1))
    assert reply[:5] == b"SWASR" and reply[7:] == b"P\r\n", reply
    return int(reply[5:7], 16)


@pytest.fixture(scope="module", params=BOARDS)
def pair_robot(request):
    """Each gateway board in turn with the slaves of SLAVES, traced, with the
    control socket; the gateway may be reset on purpose."""
    gateway = request.param
    require_builds([gateway])
    slaves = [(SLAVES[a], a, require_slave(SLAVES[a], a)) for a in (M128S, M32D)]
    sim = SimBoard(gateway, trace=True, control=True, slaves=slaves)
    sim.expect_resets = True
    with running(sim) as b:
        yield b


@pytest.fixture
def pair_rb(pair_robot):
    """pair_robot for one test: running, its input read, no bus fault
    armed, both slaves cleared (clear); after it, no fault armed and the
    board's defaults (restore)."""
    robot = pair_robot
    assert robot.sim.running, robot.sim.stderr
    robot.gw.reset_input_buffer()
    robot.sim.control.i2c_disarm()
    for addr in SLAVES:
        clear(robot, addr)
    yield robot
    robot.sim.control.i2c_disarm()
    robot.restore()


#: Simulator options of the driver test modules: a module sets
#: `DRV_SIM_OPTIONS = {"m32d": {...}, "m128s": {...}}` (SimBoard keyword
#: arguments such as spi=[...], adc={...}, aref=...) and
#: `DRV_BOARDS = ("m32d",)` to run on some boards only; `DRV_LOCAL_ONLY =
#: True` keeps a module on the gateways' own drivers.
@pytest.fixture(scope="module")
def drv_sim(request):
    board_name, addr = target(request.param)
    options = dict(getattr(request.module, "DRV_SIM_OPTIONS", {}).get(board_name, {}))
    if addr is None:
        require_builds([board_name])
        sim = SimBoard(board_name, trace=True, control=True, **options)
    else:
        require_builds([GATEWAY_OF_SLAVES])
        elf = require_slave(board_name, addr)
        # the target board's devices and inputs go to the slave
        slave_opts = {k: options.pop(k) for k in ("spi",) if k in options}
        sim = SimBoard(GATEWAY_OF_SLAVES, trace=True, control=True,
                       slaves=[(board_name, addr, elf)],
                       extra_args=tuple(a for spec in slave_opts.get("spi", [])
                                        for a in ("--spi", "%02X/%s" % (addr, spec))))
    with running(sim, lambda s: DrvBench(s, board_name, addr)) as b:
        if addr is not None:
            # the slave's analog inputs, through the control socket
            for ch, mv in sorted(options.get("adc", {}).items()):
                b.ctl.adc(ch, mv)
            if options.get("avcc") is not None:
                b.ctl.avcc(options["avcc"])
            if options.get("aref") is not None:
                b.ctl.aref(options["aref"])
        yield b


def pytest_generate_tests(metafunc):
    if "drv_sim" in metafunc.fixturenames:
        boards = getattr(metafunc.module, "DRV_BOARDS", BOARDS)
        local_only = getattr(metafunc.module, "DRV_LOCAL_ONLY", False)
        targets = [t for t in DRV_TARGETS
                   if target(t)[0] in boards and not (local_only and "@" in t)]
        metafunc.parametrize("drv_sim", targets, indirect=True, scope="module")


@pytest.fixture
def drv(drv_sim):
    """The module's board for a driver test; every driver is put back after."""
    yield from for_each_test(drv_sim, tidy=DrvBench.drv_restore)


# --- known defects (open work of issue 3) -----------------------------------
# Each entry marks tests that fail today for a reason written down here and in
# the notes. strict: the test fails every run, so an XPASS (the defect
# gone) fails the suite until the entry is removed. Not strict: the failure
# comes and goes (timing), so it may pass.
KNOWN_DEFECTS = [
    # none open
]


def pytest_collection_modifyitems(config, items):
    for item in items:
        for pattern, strict, reason in KNOWN_DEFECTS:
            # "module::*[param" matches every test of the module with that param
            prefix, _, param = pattern.partition("*")
            if item.nodeid.startswith(prefix) and param in item.nodeid:
                item.add_marker(pytest.mark.xfail(reason=reason, strict=strict))
                break


def pytest_terminal_summary(terminalreporter, config):
    """The sensor drivers' readings of this run, with or without -s."""
    rows = config.stash.get(SENSOR_READINGS, [])
    if rows:
        terminalreporter.section("sensor readings (build/sensor-readings.txt)")
        for row in rows:
            terminalreporter.write_line(row)


def cli_runner(port: str, capsys, monkeypatch):
    """run(*argv, stdin="") runs the `orfa` command in this process on
    `port` and gives (exit status, stdout, stderr)."""
    import io

    from orfa import cli

    def run(*argv, stdin=""):
        monkeypatch.setattr("sys.stdin", io.StringIO(stdin))
        try:
            status = cli.main(["--port", port, "--timeout", "5"] + list(argv))
        except SystemExit as exc:
            status = exc.code
        out, err = capsys.readouterr()
        return status, out, err
    return run
