"""The watchdog, the reset causes and the link-loss failsafe, at the pins
(docs/registers.md "Reliability" and "sys", docs/simulator.md "Faults and
resets").

Each test starts fresh simulators (they hang and reset boards, which the
shared driver fixtures forbid), on every driver target: each board's own
drivers behind its gateway, and each board as a slave of an M32-D gateway.
Time is simulated time: requests go onto the serial line at chosen cycles
(the control request `rx`), results are read from the trace and the pins.
"""

import pytest

from conftest import (DRV_TARGETS, F_CPU, GATEWAY_OF_SLAVES, SERVO_FRAME, DrvBench,
                      require_builds, require_slave, running, target)
from orfa import boards
from orfa.sim import SimBoard, sent_lines

MS = F_CPU // 1000                  # cycles per millisecond
BYTE = 640                          # cycles per byte at 115200 baud
#: What recovering from a hang may take at most (the brief: 0.5 s).
RECOVERY_MAX = F_CPU // 2
#: The failsafe timeout the tests set, and how late its effect may come:
#: the clock's tick (2048 cycles) and the main loop's current request, then
#: for servos the end of the 20 ms frame whose widths were already set.
FAILSAFE_MS = 100
MOTOR_LATE = 1 * MS
SERVO_LATE = SERVO_FRAME + 4 * MS
SERVO_CH = 3
#: A GPIO line no other function holds: (port index in the GPIO driver, line).
GPIO_LINE = {"m32d": (2, 3), "m128s": (0, 0)}


@pytest.fixture(params=DRV_TARGETS)
def fresh(request):
    """A fresh simulator for one target, as DrvBench (local or slave)."""
    board, addr = target(request.param)
    if addr is None:
        require_builds([board])
        sim = SimBoard(board, trace=True, control=True)
    else:
        require_builds([GATEWAY_OF_SLAVES])
        sim = SimBoard(GATEWAY_OF_SLAVES, trace=True, control=True,
                       slaves=[(board, addr, require_slave(board, addr))])
    with running(sim, lambda s: DrvBench(s, board, addr)) as b:
        b.sim.expect_resets = True      # these tests reset boards on purpose
        yield b


def sys_reg(b):
    return b.lay["sys"]


def gpio_pin(b):
    port, line = GPIO_LINE[b.board]
    return "%s%d" % (b.lay["gpio_ports"][port], line), port, line


def set_everything(b):
    """A servo pulsing, a motor running (M32-D), a GPIO line driven high."""
    lay = b.lay
    b.wr(lay["servo"] + 1, bytes([SERVO_CH, 0x05, 0xDC]))         # 1500 us
    if lay["motor"] is not None:
        b.wr(lay["motor"], b"\x80\x00\x01\x00")                   # PWM1 half, DIR1 back
    name, port, line = gpio_pin(b)
    bit = 1 << line
    b.wr(lay["gpio_mode"] + port, bytes([bit, bit]))
    b.wr(lay["gpio_val"] + port, bytes([bit, bit]))
    b.wait(3 * SERVO_FRAME)
    assert b.pin(name) == (1, "out")
    assert "high" in b.measure(servo_pin(b), b.now() - 2 * SERVO_FRAME)
    if lay["motor"] is not None:
        assert "high" in b.measure("D5", b.now() - 10 * 368)


def servo_pin(b):
    return b.lay["servo_pins"][SERVO_CH]


def stream(b, start, line, until):
    """Schedule `line` (a request and its terminator) again and again on the
    gateway's serial line from cycle `start` (or a little after now, should
    the simulation have passed it while we asked) until `until`; returns
    the cycle the last one's terminator arrives."""
    return b.sim.control.rx_stream(start, line, until, 20 * MS)[1]


def reply_lines(b, since_cycle):
    """[(cycle of the first byte, line)] the gateway sent from since_cycle on."""
    return sent_lines(b.sim.trace_events(kinds=["uart tx"]), since_cycle)


def resets(b, since_cycle=0):
    """The trace's reset events of the target board: [(cycle, cause)]."""
    out = []
    for e in b.sim.trace_events(kinds=["reset"]):
        # "reset <cause>" (the gateway), "reset <SS> <cause>" (slave SS)
        who = e.fields[0] if len(e.fields) == 2 else None
        if who == ("%02X" % b.addr if b.slave else None) and e.cycle >= since_cycle:
            out.append((e.cycle, e.fields[-1]))
    return out


def hang_and_recover(b, count):
    """`fault hang` on the target board; requests stream in (every 10 ms)
    until it answers again. Returns (hang cycle, reset cycle, cycle of the
    first correct reply)."""
    ctl = b.ctl
    req = b.req("S AA 00 00 S AB 01 P")
    want = "SWAASR%02XP" % count
    # padded with spaces (an empty tail of the line) to 10 ms a request: a
    # request to a hung slave waits for the bus that long, so none piles up
    line = (req + " " * (128 - len(req)) + "\r").encode()
    t0 = ctl.fault_hang()
    # (from a little after now: the simulation runs on while we ask)
    end = stream(b, b.now() + 30 * MS, line, t0 + RECOVERY_MAX + 100 * MS)
    b.wait(end - b.now() + 20 * MS)
    got = [(c, l) for c, l in reply_lines(b, t0) if l == want]
    rs = resets(b, t0)
    assert rs, "no reset after the hang"
    assert rs[0][1] == "watchdog", rs
    assert got, "the board never answered %r after the hang" % req
    return t0, rs[0][0], got[0][0]


def check_reset_state(b):
    """Servo silent, motor stopped, GPIO line an input, registers so."""
    lay = b.lay
    since = b.now()
    b.wait(3 * SERVO_FRAME)
    assert b.edges(servo_pin(b), since) == []
    assert b.ctl.level(servo_pin(b)) == 0
    assert b.rd(lay["servo"] + 1, 8) == bytes(8)
    if lay["motor"] is not None:
        for sig in ("D5", "D4", "B0", "B1"):
            assert b.pin(sig) == (0, "out"), sig
            assert b.edges(sig, since) == [], sig
        assert b.rd(lay["motor"], 4) == bytes(4)
    name, port, line = gpio_pin(b)
    assert b.pin(name) == (0, "in")
    assert b.rd(lay["gpio_mode"] + port, 1)[0] & (1 << line) == 0


def test_hang_ends_in_a_watchdog_reset_and_the_reset_state(fresh):
    b = fresh
    count = b.driver_count()
    assert b.gw.reset_cause(b.addr) == {"power"}
    b.gw.clear_reset_cause(b.addr)
    set_everything(b)
    if not b.slave:
        assert b.ask("L B0") == b"LB0\r\n"
    t0, reset, answer = hang_and_recover(b, count)
    # the watchdog's 250 ms (its oscillator: 256 ms) after the last feed
    assert 0.2 * F_CPU <= reset - t0 <= 0.3 * F_CPU, reset - t0
    assert answer - t0 <= RECOVERY_MAX, answer - t0
    b.settle()
    if not b.slave:
        assert b.ask("L") == b"LAA\r\n"
    check_reset_state(b)
    assert b.gw.reset_cause(b.addr) == {"watchdog"}
    # and again: the watchdog's period holds after a watchdog reset too
    b.gw.clear_reset_cause(b.addr)
    set_everything(b)
    t0, reset, answer = hang_and_recover(b, count)
    assert 0.2 * F_CPU <= reset - t0 <= 0.3 * F_CPU, reset - t0
    assert answer - t0 <= RECOVERY_MAX, answer - t0
    b.settle()
    check_reset_state(b)
    assert b.gw.reset_cause(b.addr) == {"watchdog"}


def test_reset_causes_accumulate_until_cleared(fresh):
    b = fresh
    gw, addr, ctl = b.gw, b.addr, b.ctl
    assert gw.reset_cause(addr) == {"power"}
    assert b.rd(sys_reg(b), 1) == b"\x01"
    gw.clear_reset_cause(addr)
    assert gw.reset_cause(addr) == frozenset()

    def reset(cause):
        ctl.reset(cause)
        b.wait(20 * MS)
        b.settle()

    reset("external")
    assert gw.reset_cause(addr) == {"external"}
    reset("brownout")
    assert gw.reset_cause(addr) == {"external", "brownout"}
    # a clear of some: the others stay
    gw.clear_reset_cause(addr, ["external"])
    assert gw.reset_cause(addr) == {"brownout"}
    reset("power")                                  # SRAM lost: afresh
    assert gw.reset_cause(addr) == {"power"}
    b.wr(sys_reg(b), b"\xff")                       # S AA <R> FF P clears all
    assert b.rd(sys_reg(b), 1) == b"\x00"
    # one byte only: refused, nothing cleared
    reset("external")
    b.wr_refused(sys_reg(b), b"\x02\x00", 0x01)
    assert gw.reset_cause(addr) == {"external"}
    assert [c for _, c in resets(b)] == ["external", "brownout", "power", "external"]


def test_failsafe_register(fresh):
    b = fresh
    fs = sys_reg(b) + 1
    assert b.gw.failsafe(b.addr) == 0                     # off after reset
    b.gw.set_failsafe(b.addr, 1234)
    assert b.rd(fs, 2) == b"\x04\xd2"
    assert b.gw.failsafe(b.addr) == 1234
    b.wr_refused(fs, b"\x46\x51", 0x02)                   # 18001 ms: too long
    b.wr_refused(fs, b"\x01", 0x01)
    b.wr_refused(fs, b"\x00\x10\x00", 0x01)
    assert b.gw.failsafe(b.addr) == 1234
    b.wr(fs, b"\x00\x00")
    assert b.gw.failsafe(b.addr) == 0
    with pytest.raises(ValueError):
        b.gw.set_failsafe(b.addr, boards.FAILSAFE_MAX_MS + 1)


def keepalive_line(b):
    """A request that reaches the target board (another register of it)."""
    req = b.req("S AA 01 S AB 01 P")           # its status register
    return (req + " " * (60 - len(req)) + "\r").encode()


def last_heard(b, since_cycle, stream_end):
    """The cycle the target board last heard a request: the gateway, the
    terminator of the last line; a slave, its own address on the bus."""
    if not b.slave:
        return stream_end
    own = "%02X" % b.addr, "%02X" % (b.addr | 1)
    cycles = [e.cycle for e in b.sim.trace_events(kinds=["twi addr"])
              if e.cycle >= since_cycle and e.fields[0] in own and e.fields[1] == "ack"]
    assert cycles, "no request reached the slave"
    return cycles[-1]


def quiet_after(b, sig, since):
    """The cycle of sig's last edge at or after `since` (None: none)."""
    edges = b.edges(sig, since)
    return edges[-1][0] if edges else None


@pytest.mark.parametrize("other", [False, True], ids=["own", "other-address"])
def test_failsafe_trips_when_the_link_goes_quiet(fresh, other):
    """FAILSAFE 100 ms: requests every 5 ms for 400 ms keep servo and motor
    running; then only requests to another address (slave targets) or
    none: the servo stops pulsing and the motor's PWM goes low within the
    timeout and a small bound, and the registers say so."""
    b = fresh
    if other and not b.slave:
        pytest.skip("requests to another address reach a gateway too")
    lay = b.lay
    set_everything(b)
    # FAILSAFE on, then the requests, all on the line at chosen cycles: no
    # wall-clock pause between them can trip it early
    fs = b.req("S AA %02X %04X P" % (sys_reg(b) + 1, FAILSAFE_MS)).encode() + b"\r"
    start = b.now() + 30 * MS
    fs_end = stream(b, start, fs, 0)
    start = min(start, fs_end - len(fs) * BYTE)
    line = keepalive_line(b)
    end = stream(b, fs_end, line, fs_end + 400 * MS)
    if other:
        # the bus stays busy, but never with the slave's own address
        miss = b"S 1C 00 S 1D 01 P" + b" " * 40 + b"\r"
        stream(b, end, miss, end + 300 * MS)
    b.wait(end - b.now() + 300 * MS)
    heard = last_heard(b, start, end)
    # running while requests came
    pulses = b.highs(servo_pin(b), start, heard)
    assert len(pulses) >= 350 // 20, len(pulses)
    assert all(abs(high - 11059) <= 8 for _, high, _ in pulses), pulses[:3]
    servo_stop = quiet_after(b, servo_pin(b), start)
    assert servo_stop is not None
    assert heard + FAILSAFE_MS * MS <= servo_stop + SERVO_FRAME
    assert servo_stop - heard <= FAILSAFE_MS * MS + SERVO_LATE, servo_stop - heard
    assert b.ctl.level(servo_pin(b)) == 0
    if lay["motor"] is not None:
        pwm_stop = quiet_after(b, "D5", start)
        assert FAILSAFE_MS * MS <= pwm_stop - heard <= FAILSAFE_MS * MS + MOTOR_LATE, \
            pwm_stop - heard
        assert b.pin("D5") == (0, "out")
        assert b.pin("B0") == (1, "out")                   # direction kept
    b.settle()
    # exactly as if the host had written it
    assert b.rd(lay["servo"] + 1, 8) == bytes(8)
    if lay["motor"] is not None:
        assert b.rd(lay["motor"], 4) == b"\x00\x00\x01\x00"
    name, _, _ = gpio_pin(b)
    assert b.pin(name) == (1, "out")                       # GPIO untouched
    assert resets(b, start) == []


def test_failsafe_off_never_trips(fresh):
    b = fresh
    set_everything(b)
    b.gw.set_failsafe(b.addr, FAILSAFE_MS)
    b.gw.set_failsafe(b.addr, 0)
    since = b.now()
    b.wait(500 * MS)
    m = b.measure(servo_pin(b), 20, since)
    assert "high" in m and m["n"] >= 20, m
    if b.lay["motor"] is not None:
        assert "high" in b.measure("D5", 10, b.now() - 5 * MS)
