"""The typed API (orfa.Board) against simulated boards, measured on the pins:
an M32-D gateway's own drivers, an M128-S gateway's, and an M128-S and an
M32-D slave behind the M32-D gateway (one robot). Servo widths and angles,
motor duty and direction, ADC volts, GPIO levels, an SPI EEPROM, the status
register's reasons, reset causes, 300 pipelined requests and noise on the
line. The exact requests each call sends: tests/host/test_api_requests.py."""

import time

import pytest

from conftest import (WIDTH_TOL, DRV_LAYOUT, F_CPU, REPLY_TIMEOUT, SERVO_FRAME, require_builds,
                      require_slave, running, us_to_cycles)
from orfa import (BadLengthError, BadValueError, Board, DataNackError, Gateway,
                  NoDriverError, NotWritableError, OrfaError, PinBusyError,
                  ProtocolError, Read, Status, Write)
from orfa.sim import SimBoard

#: target -> (board, bus address or None for the gateway's own drivers)
TARGETS = {"m32d": ("m32d", None), "m128s": ("m128s", None),
           "m128s@10": ("m128s", 0x10), "m32d@12": ("m32d", 0x12)}
#: the chip select of each board's SPI EEPROM (a GPIO line)
SPI_CS = {"m32d": "C2", "m128s": "A0"}
ADC_MV = 1000
PWM_PERIOD = 368                         # docs/registers.md "Motors"


@pytest.fixture(scope="module")
def sims():
    """Two simulators: the robot (M32-D gateway, M128-S slave 0x10, M32-D
    slave 0x12) and an M128-S gateway on its own."""
    require_builds(["m32d", "m128s"])
    slaves = [("m128s", 0x10, require_slave("m128s", 0x10)),
              ("m32d", 0x12, require_slave("m32d", 0x12))]
    robot = SimBoard("m32d", control=True, adc={0: ADC_MV}, spi=["eeprom25@" + SPI_CS["m32d"]],
                     slaves=slaves,
                     extra_args=("--spi", "10/eeprom25@" + SPI_CS["m128s"],
                                 "--spi", "12/eeprom25@" + SPI_CS["m32d"]))
    single = SimBoard("m128s", control=True, adc={0: ADC_MV}, spi=["eeprom25@" + SPI_CS["m128s"]])
    with running(robot, _Open) as r, running(single, _Open) as s:
        for addr in (0x10, 0x12):
            robot.control.slave(addr).adc(0, ADC_MV)
        yield {"robot": (robot, r.gw), "single": (single, s.gw)}


class _Open:
    """A simulator's Gateway, closed when `running` stops the simulator."""

    def __init__(self, sim):
        self.gw = Gateway(sim.port, timeout=REPLY_TIMEOUT)

    def close(self):
        self.gw.close()


class Target:
    """A Board on a simulated board, its pins (ctl) and layout."""

    def __init__(self, sims, name):
        self.name = name
        self.kind, addr = TARGETS[name]
        self.sim, gw = sims["single"] if name == "m128s" else sims["robot"]
        self.board = Board(gw, addr)
        self.ctl = self.sim.control if addr is None else self.sim.control.slave(addr)
        self.lay = DRV_LAYOUT[self.kind]

    def servo_pin(self, ch):
        return self.lay["servo_pins"][ch]

    def restore(self):
        b = self.board
        b.servo.off()
        if b.has("motor"):
            b.motor.set_all(0, 0)
        b.adc.configure([], "avcc", 10)
        b.spi.configure()
        for port in b.gpio.ports:
            b.gpio.set_modes(port, 0)
            b.gpio.write(port, 0)
        b.set_failsafe(0)


@pytest.fixture(params=list(TARGETS))
def t(request, sims):
    target = Target(sims, request.param)
    yield target
    target.restore()


def settle(t, frames=3):
    """Let new widths run (they start at the next frame), then record
    `frames` frames; the cycle the recording began."""
    t.ctl.wait(2 * SERVO_FRAME)
    since = t.ctl.time()
    t.ctl.wait(frames * SERVO_FRAME)
    return since


# --- introspection ------------------------------------------------------------

def test_introspection_finds_the_board(t):
    b = t.board
    assert b.map is not None and b.map.board == t.kind
    assert b.is_local == (t.name in ("m32d", "m128s"))
    assert b.has("motor") == (t.kind == "m32d")
    # the last driver is sys: its RESET register is that record's start
    assert b.register("sys", "RESET") == b.drivers[-1].start
    if t.kind == "m128s":
        with pytest.raises(NoDriverError):
            b.motor


# --- servo --------------------------------------------------------------------

def test_servo_width_and_angle_on_the_pin(t):
    s = t.board.servo
    s.set_width(3, 1500)
    s.set_angle(5, -45)                             # the manual: 1200 us
    assert s.width(3) == 1500 and s.angle(5) == -45.0
    assert s.pulsing() == {3, 5}
    since = settle(t)
    for ch, us in ((3, 1500), (5, 1200)):
        m = t.ctl.measure(t.servo_pin(ch), 50, since)
        lo, hi, _ = m["high"]
        want = us_to_cycles(us)
        assert abs(lo - want) <= WIDTH_TOL and abs(hi - want) <= WIDTH_TOL, (ch, us, m)
    s.off(3)
    assert s.pulsing() == {5}
    assert s.widths()[:6] == [0, 0, 0, 0, 0, 1200]


def test_servo_every_channel_in_batches(t):
    """All channels in one call: SP writes of 16 triples, pipelined; read
    back in 28-channel reads."""
    s = t.board.servo
    want = {ch: 1000 + 10 * ch for ch in range(s.channels)}
    s.set_widths(want)
    assert s.widths() == [want[ch] for ch in range(s.channels)]
    assert s.pulsing() == set(range(s.channels))
    s.off()
    assert s.pulsing() == set()


# --- motor --------------------------------------------------------------------

@pytest.mark.parametrize("t", ["m32d", "m32d@12"], indirect=True)
def test_motor_duty_and_direction_on_the_pins(t):
    m = t.board.motor
    m.set(1, 128)
    m.set(2, -64)
    assert (m.get(1), m.get(2)) == (128, -64)
    t.ctl.wait(4 * PWM_PERIOD)
    since = t.ctl.time()
    t.ctl.wait(60 * PWM_PERIOD)
    for pin, duty in (("D5", 128), ("D4", 64)):
        got = t.ctl.measure(pin, 50, since)
        for high in got["high"][:2]:
            assert abs(high / PWM_PERIOD - duty / 255) <= 1 / 368, (pin, got)
    assert t.ctl.pin("B0") == (0, "out") and t.ctl.pin("B1") == (1, "out")
    m.stop()
    assert m.duties() == [0, 0]                     # directions kept, duty 0
    t.ctl.wait(4 * PWM_PERIOD)
    assert t.ctl.pin("D5") == (0, "out") and t.ctl.pin("B1") == (1, "out")


# --- ADC ----------------------------------------------------------------------

def test_adc_volts_from_the_simulated_input(t):
    adc = t.board.adc
    adc.configure([0, 1], "avcc", 10)
    assert adc.config() == ("avcc", 10, (0, 1))
    t.ctl.wait(int(0.01 * F_CPU))                 # valid within 10 ms
    volts = adc.volts()
    assert abs(volts[0] - ADC_MV / 1000) <= 2 * 5.0 / 1024, volts
    assert volts[2:] == [0.0] * 6                   # not enabled
    adc.configure([0], "internal", 8)
    t.ctl.wait(int(0.01 * F_CPU))
    raw = adc.read()
    assert abs(raw[0] - ADC_MV / 2560 * 256) <= 2, raw
    assert abs(adc.volts()[0] - ADC_MV / 1000) <= 2 * 2.56 / 256


# --- GPIO ---------------------------------------------------------------------

def test_gpio_levels(t):
    g = t.board.gpio
    assert g.ports == t.lay["gpio_ports"]
    g.set_modes("a", 0x10, 0x30)                    # A4 output, A5 input
    g.write("A", 0x10, 0x30)
    assert g.modes("A") & 0x30 == 0x10
    assert t.ctl.pin("A4") == (1, "out")
    try:
        t.ctl.drive("A5", 1)
        assert g.read("A") & 0x30 == 0x30
        t.ctl.drive("A5", 0)
        assert g.read("A") & 0x30 == 0x10
    finally:
        t.ctl.drive("A5", None)


# --- SPI ----------------------------------------------------------------------

def test_spi_transfer_with_an_eeprom(t):
    b = t.board
    cs = SPI_CS[t.kind]
    b.gpio.write(cs[0], 1 << int(cs[1]), 1 << int(cs[1]))    # pull-up: deselected
    b.spi.bind(0, cs[0], int(cs[1]))
    assert b.spi.config()["channels"][0] == (cs[0], int(cs[1]))
    t.ctl.spi()                                     # forget earlier exchanges
    assert b.spi.transfer(0, b"\x05\x00") == b"\xff\x00"      # RDSR: idle
    b.spi.transfer(0, b"\x06")                      # WREN
    assert b.spi.transfer(0, b"\x05\x00")[1] & 0x02  # write enable latch
    data = bytes(range(0x41, 0x41 + 8))
    b.spi.transfer(0, b"\x02\x30" + data)           # WRITE at 0x30
    t.ctl.wait(36864 + 2000)                        # the 5 ms write cycle
    got = b.spi.transfer(0, b"\x03\x30" + bytes(len(data)))
    assert got[2:] == data
    log = t.ctl.spi()
    assert [e["cs"] for e in log] == [cs] * 5
    assert log[-1]["mosi"] == b"\x03\x30" + bytes(8) and log[-1]["miso"] == got


# --- refusals -------------------------------------------------------------------

def test_bad_value_is_refused_with_its_reason(t):
    b = t.board
    with pytest.raises(ValueError):
        b.servo.set_width(40, 1500)                 # the host knows the channels
    with pytest.raises(BadValueError) as e:
        b.write("servo", "SP", [40, 0x05, 0xDC])    # the board refuses channel 40
    assert e.value.status is Status.BAD_VALUE and e.value.addr == b.addr
    # the gateway's own drivers, and a slave's byte after the bad one: ERROR 07
    assert isinstance(e.value.__cause__, DataNackError)
    assert str(e.value).startswith("0x%02X servo SP: write refused: BAD_VALUE (" % b.addr)
    assert b.status() is Status.BAD_VALUE
    assert b.servo.pulsing() == set()


def test_refusal_found_when_the_frame_ends(t):
    """FAILSAFE above 18000 ms: decided when the frame ends; a slave then
    acknowledges every byte and only its status register tells."""
    b = t.board
    with pytest.raises(BadValueError) as e:
        b.write("sys", "FAILSAFE", [0x4E, 0x20])    # 20000 ms
    assert (e.value.__cause__ is None) == (not b.is_local)
    with pytest.raises(BadLengthError):
        b.write("sys", "RESET", [0x01, 0x02])
    with pytest.raises(NotWritableError):
        b.write("adc", "RD", [0x00])
    b.set_failsafe(18000)
    assert b.failsafe() == 18000


@pytest.mark.parametrize("t", ["m32d", "m32d@12"], indirect=True)
def test_pin_busy(t):
    """Servo 14 and motor 1 share PD5 on the M32-D."""
    b = t.board
    b.servo.set_width(14, 1500)
    with pytest.raises(PinBusyError) as e:
        b.motor.set(1, -100)
    assert "PIN_BUSY" in str(e.value) and e.value.register == "motor PWM1"
    assert b.status() is Status.PIN_BUSY
    assert b.motor.duties() == [0, 0]               # neither PWM1 nor DIR1 changed
    b.servo.off(14)
    b.motor.set(1, -100)
    assert b.motor.get(1) == -100


@pytest.mark.parametrize("t", ["m32d", "m32d@12"], indirect=True)
def test_pin_busy_names_the_busy_line(t):
    """Motor.set writes from PWM1 (both motors in one write), so the board's
    refusal names PWM1 whichever line is busy: the error names the motor
    whose line a servo holds (servo 15 holds motor 2's PWM2, PD4)."""
    b = t.board
    b.servo.set_width(15, 1500)
    try:
        with pytest.raises(PinBusyError) as e:
            b.motor.set(2, 100)
        assert e.value.register == "motor PWM2", str(e.value)
        assert "PWM1" not in str(e.value)
        assert b.status() is Status.PIN_BUSY        # nothing was read to find out
        b.motor.set(1, 100)                         # PWM1 is free
        with pytest.raises(PinBusyError) as e:
            b.motor.set_all(0, 50)                  # only motor 2 needs its line
        assert e.value.register == "motor PWM2", str(e.value)
    finally:
        b.servo.off(15)
        b.motor.set_all(0, 0)


# --- reset cause ----------------------------------------------------------------

@pytest.mark.parametrize("t", ["m128s@10", "m32d@12"], indirect=True)
def test_reset_cause(t):
    """The slaves are reset here (the gateways' own resets: test_drv_reset.py)."""
    b = t.board
    b.clear_reset_cause()
    assert b.reset_cause() == frozenset()
    t.ctl.reset("external")
    t.ctl.wait(int(0.05 * F_CPU))                 # the slave starts again
    assert b.reset_cause() == {"external"}
    b.clear_reset_cause(["external"])
    assert b.reset_cause() == frozenset()


# --- the line: pipelining and noise -------------------------------------------------

def test_300_requests_pipelined_in_order(sims):
    """Introspection records of the gateway and both slaves, each record a
    different reply, 300 requests with up to 255 characters in flight."""
    _, gw = sims["robot"]
    lines, want = [], []
    boards = [Board(gw), Board(gw, 0x10), Board(gw, 0x12)]
    for i in range(300):
        b = boards[i % 3]
        recs = b.drivers
        n = 1 + (i // 3) % len(recs)
        r = recs[n - 1]
        lines.append("S %02X 00 %02X S %02X 06 P" % (b.addr, n, b.addr | 1))
        want.append("SWAASR%04X%02X%02X%02X%02XP" % (r.uid, r.major, r.minor, r.start, r.count))
    assert gw.run(lines) == want


class NoisyPort:
    """The simulator's port with noise added: `into` bytes go to the board
    in the middle of the first write of a request stream that passes
    `after` requests; `garble` reply line number k comes back garbled."""

    def __init__(self, port, into=b"", after=0, garble=None):
        self.port, self.into, self.after, self.garble = port, into, after, garble
        self.requests = 0
        self.lines = 0

    def write(self, data):
        n = data.count(b"\n")
        if self.into and self.requests <= self.after < self.requests + n:
            cut = 0
            for _ in range(self.after - self.requests + 1):
                cut = data.index(b"\n", cut) + 1
            data = data[:cut] + self.into + data[cut:]
            self.into = b""
        self.requests += n
        return self.port.write(data)

    def read_until(self, expected=b"\n"):
        line = self.port.read_until(expected)
        if line.endswith(b"\n"):
            self.lines += 1
            if self.lines == self.garble:
                line = b"S\x13" + line[2:]
        return line

    def __getattr__(self, name):
        return getattr(self.port, name)


def test_stale_reply_dropped_by_a_marker(sims):
    """Bytes on the board's receive line make a reply nobody asked for:
    the next call drops it (a `V` marker) and gets its own reply."""
    sim, gw = sims["robot"]
    b = Board(gw)
    b.servo.set_width(2, 1700)
    ctl = sim.control
    _, end = ctl.rx_stream(ctl.time() + 2000, b"Zz\n", 0, 2000)
    ctl.wait(max(1000, end + 20000 - ctl.time()))
    # the board has answered Zz in simulated time; its reply reaches the port
    # when the kernel hands it over (wall time): wait for it, do not guess
    deadline = time.monotonic() + REPLY_TIMEOUT
    while not gw.serial.in_waiting:
        assert time.monotonic() < deadline, "the reply to Zz never reached the port"
        time.sleep(0.01)
    before = gw.resyncs
    assert b.servo.width(2) == 1700
    assert gw.resyncs == before + 1
    b.servo.off()


@pytest.mark.parametrize("noise", ["into", "garble"])
def test_noise_in_a_pipelined_run(sims, noise):
    """A line of noise to the board in the middle of 120 pipelined requests
    (its `ERROR 02` is one reply too many), or a reply garbled on its way
    back: the requests it hit get errors, the others their own replies,
    never another's; the next run is in step."""
    _, gw = sims["robot"]
    lines = ["S AA 00 %02X S AB 06 P" % (1 + i % 7) for i in range(120)]
    want = gw.run(lines)
    port = gw.serial
    gw.serial = NoisyPort(port, **({"into": b"Q\n", "after": 60} if noise == "into"
                                   else {"garble": 40}))
    try:
        results = gw.transactions([[Write(0xAA, bytes([0, 1 + i % 7])), Read(0xAA, 6)]
                                   for i in range(120)])
    finally:
        gw.serial = port
    got = ["SWAASR%sP" % r[1].data.hex().upper() if isinstance(r, list) else r for r in results]
    errors = [i for i, g in enumerate(got) if isinstance(g, OrfaError)]
    assert all(got[i] == want[i] for i in range(120) if i not in errors)
    assert errors and all(isinstance(got[i], ProtocolError) for i in errors), got
    if noise == "garble":
        assert errors == [39]                       # its reply line was the 40th
    else:
        assert min(errors) >= 60 - 1
    assert gw.run(lines) == want


def test_docs_example_prints_what_the_docs_show(capsys):
    """docs/python.md's example session, run: it prints what the page says."""
    import re
    from pathlib import Path
    text = (Path(__file__).resolve().parents[2] / "docs" / "python.md").read_text()
    code, shown = re.search(r"```python\n(.*?)```\n\nprints\n\n```\n(.*?)```", text, re.S).groups()
    require_builds(["m32d"])
    exec(compile(code, "docs/python.md", "exec"), {})
    assert capsys.readouterr().out == shown
