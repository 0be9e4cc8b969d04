"""Motor driver (OR-AVR-M32-D; docs/registers.md "Motors"), on the pins:
PWM1 = PD5 (OC1A), PWM2 = PD4 (OC1B), DIR1 = PB0, DIR2 = PB1."""

import pytest

from conftest import F_CPU, SERVO_FRAME
from orfa.simctl import SimControlError

DRV_BOARDS = ("m32d",)
PWM_PERIOD = 368                    # F_CPU / 368 = 20.035 kHz
PWM_PINS = ("D5", "D4")
DIR_PINS = ("B0", "B1")
BAD_LENGTH, BAD_VALUE, PIN_BUSY = 0x01, 0x02, 0x03


def reg(drv, i=0):
    return drv.lay["motor"] + i


def settle(drv):
    drv.wait(4 * PWM_PERIOD)
    since = drv.now()
    drv.wait(60 * PWM_PERIOD)
    return since


def check_pwm(drv, pin, pwm, since):
    m = drv.measure(pin, since)
    if pwm == 0:
        assert m == {"steady": 0}, (pin, m)
        assert drv.edges(pin, since) == [], pin
        assert drv.pin(pin) == (0, "out"), pin
    elif pwm == 255:
        assert m == {"steady": 1}, (pin, m)
        assert drv.edges(pin, since) == [], pin
    else:
        assert "high" in m and m["n"] >= 40, (pin, m)
        assert m["period"][:2] == (PWM_PERIOD, PWM_PERIOD), (pin, m)
        for high in m["high"][:2]:
            # docs: duty = PWM/255 within 1/368 (brief: 1/256)
            assert abs(high / PWM_PERIOD - pwm / 255) <= 1 / 368, (pin, pwm, m)


def check_state(drv, pwm1, pwm2, dir1, dir2):
    since = settle(drv)
    check_pwm(drv, "D5", pwm1, since)
    check_pwm(drv, "D4", pwm2, since)
    assert drv.pin("B0") == (dir1, "out")
    assert drv.pin("B1") == (dir2, "out")
    assert drv.rd(reg(drv), 4) == bytes([pwm1, pwm2, dir1, dir2])


@pytest.mark.parametrize("pwm", [0, 1, 2, 64, 127, 128, 200, 254, 255])
def test_pwm_duty_on_both_motors(drv, pwm):
    drv.wr(reg(drv, 0), bytes([pwm]))
    drv.wr(reg(drv, 1), bytes([255 - pwm]))
    check_state(drv, pwm, 255 - pwm, 0, 0)


def test_pwm_frequency(drv):
    """60 periods taken in one window fixed in simulated cycles (SimControl
    .window): every period exactly 368 cycles, every pulse the same width,
    and both lines rise together at the timer's BOTTOM."""
    pwm = {"D5": 0x80, "D4": 0x40}
    drv.wr(reg(drv), bytes([pwm["D5"], pwm["D4"]]))
    drv.wait(4 * PWM_PERIOD)
    start, end, edges = drv.ctl.window(list(PWM_PINS), 60 * PWM_PERIOD)
    rises = {}
    for pin in PWM_PINS:
        r = [c for c, level in edges[pin] if level == 1]
        f = [c for c, level in edges[pin] if level == 0 and c > r[0]]
        assert r[0] - start < PWM_PERIOD and end - r[-1] <= PWM_PERIOD, (pin, start, r, end)
        assert {b - a for a, b in zip(r, r[1:])} == {PWM_PERIOD}, (pin, r)
        highs = {fall - rise for rise, fall in zip(r, f)}
        assert len(highs) == 1, (pin, highs)
        # docs: duty = PWM/255 within 1/368 (brief: 1/256)
        assert abs(highs.pop() / PWM_PERIOD - pwm[pin] / 255) <= 1 / 368, pin
        m = drv.measure(pin, start)
        assert m["period"] == (PWM_PERIOD, PWM_PERIOD, float(PWM_PERIOD)), m
        rises[pin] = r
    assert len(rises["D5"]) >= 60
    assert rises["D5"] == rises["D4"]


def test_shortest_pulses_never_drop(drv):
    """PWM 1 and 2 (OCR 0 and 2: pulses of 1 and 3 cycles) while requests
    keep the firmware busy: every period has its pulse, exactly 368 cycles
    apart (the simulator once lost such pulses when its overflow ran after a
    multi-cycle instruction). The simulator keeps the last 1024 edges of a
    signal: checked after every few requests."""
    drv.wr(reg(drv), bytes([1, 2]))
    drv.wait(4 * PWM_PERIOD)
    periods = 0
    for _ in range(20):
        since = drv.now()
        for _ in range(3):
            assert drv.rd(reg(drv), 4) == bytes([1, 2, 0, 0])
        for pin, high in (("D5", 1), ("D4", 3)):
            edges = drv.edges(pin, since)
            rises = [c for c, level in edges if level == 1]
            falls = [c for c, level in edges if level == 0 and c > rises[0]]
            assert {b - a for a, b in zip(rises, rises[1:])} == {PWM_PERIOD}, pin
            assert {f - r for r, f in zip(rises, falls)} == {high}, pin
            periods += len(rises)
    assert periods >= 2000, periods


@pytest.mark.parametrize("dir1, dir2", [(0, 1), (1, 0), (1, 1), (0, 0)])
def test_direction_lines(drv, dir1, dir2):
    drv.wr(reg(drv, 2), bytes([dir1, dir2]))
    check_state(drv, 0, 0, dir1, dir2)


def test_four_byte_write_from_the_manual(drv):
    drv.wr(reg(drv), bytes.fromhex("80600001"))
    check_state(drv, 0x80, 0x60, 0, 1)
    assert drv.rd(reg(drv, 1), 3) == bytes.fromhex("600001")    # r..DIR2
    assert drv.rd(reg(drv, 3), 1) == b"\x01"


def test_both_motors_change_in_the_same_period(drv):
    """The write goes on the serial line at a fixed cycle of a window fixed
    in simulated time (`rx +N` inside SimControl.window), so the edges that
    show the change are all still kept when the window is read."""
    drv.wr(reg(drv), bytes([50, 200]))
    drv.wait(10 * PWM_PERIOD)
    req = b"S%s%02X9664P\n" % (drv.wa.encode(), reg(drv))
    lead = 1000
    # the request's bytes, the bus and the driver (a few ms), then 10 periods
    byte = 10 * drv.sim.control.line()["bit"]      # the PC's byte time
    span = lead + len(req) * byte + 40000 + 10 * PWM_PERIOD
    t0, end, edges = drv.ctl.window(list(PWM_PINS), span,
                                    ["rx +%d %s" % (lead, req.hex().upper())])
    assert drv.read_lines(1) == b"SWAAAP\r\n"
    if drv.slave:
        assert drv.status() == 0

    def first_new(pin, new):
        want = round(new * PWM_PERIOD / 255)
        pin_edges = edges[pin]
        assert pin_edges and pin_edges[0][0] - t0 < PWM_PERIOD, (pin, t0, pin_edges[:2])
        for i, (c, l) in enumerate(pin_edges[:-1]):
            if l == 1 and abs(pin_edges[i + 1][0] - c - want) <= 1:
                assert end - c >= 10 * PWM_PERIOD, (pin, c, end)
                return c
        raise AssertionError((pin, pin_edges[:8]))
    assert first_new("D5", 150) == first_new("D4", 100)


@pytest.mark.parametrize("register, data, status", [
    (0, "8060000100", BAD_LENGTH),      # past DIR2
    (1, "80600001", BAD_LENGTH),
    (2, "000000", BAD_LENGTH),
    (3, "0101", BAD_LENGTH),
    (2, "02", BAD_VALUE),               # DIR other than 0/1
    (3, "FF", BAD_VALUE),
    (0, "10200002", BAD_VALUE),         # atomic: the PWM bytes do not apply
    (0, "30400100", None),              # (a good write, for contrast below)
])
def test_rejected_writes_change_nothing(drv, register, data, status):
    drv.wr(reg(drv), bytes.fromhex("64C80100"))      # PWM1 100, PWM2 200, DIR1 1
    check_state(drv, 100, 200, 1, 0)
    if status is None:
        drv.wr(reg(drv, register), bytes.fromhex(data))
        check_state(drv, 0x30, 0x40, 1, 0)
        return
    t0 = drv.now()
    drv.wr_refused(reg(drv, register), bytes.fromhex(data), status)
    check_state(drv, 100, 200, 1, 0)
    for pin in DIR_PINS:
        assert drv.edges(pin, t0) == [], pin


def test_servo_14_15_borrow_stopped_motor_lines(drv):
    """A stopped motor lends its PWM line to servo 14 (PD5) / 15 (PD4);
    while the servo pulses, a non-zero PWM for that motor is refused (03);
    turning the servo on while the motor runs is refused too; turning the
    servo off gives the line back to the stopped motor (low)."""
    sp = drv.lay["servo"] + 1
    drv.wr(sp, bytes([14, 0x05, 0xDC]))                       # servo 14: 1500 us
    drv.wait(2 * SERVO_FRAME + 8192)
    since = drv.now()
    drv.wr_refused(reg(drv, 0), b"\x01", PIN_BUSY)                # motor 1 refused
    drv.wr_refused(reg(drv), bytes.fromhex("01400000"), PIN_BUSY)  # all four refused
    drv.wr(reg(drv, 1), b"\x80")                                 # motor 2 runs
    drv.wr(reg(drv, 0), b"\x00")                                 # PWM1 0 is fine
    drv.wait(5 * SERVO_FRAME)
    m = drv.measure("D5", since)
    assert abs(m["high"][0] - 11059.2) <= 8 and abs(m["high"][1] - 11059.2) <= 8, m
    assert m["period"][0] >= SERVO_FRAME - 147, m
    assert drv.rd(reg(drv), 4) == bytes([0, 0x80, 0, 0])
    check_pwm(drv, "D4", 0x80, since)
    # servo 15 while motor 2 runs: refused, whole write
    drv.wr_refused(sp, bytes([13, 0x05, 0xDC, 15, 0x05, 0xDC]), PIN_BUSY)
    assert drv.rd(sp, 32)[26:32] == bytes([0, 0, 0x05, 0xDC, 0, 0])
    # servo 14 off: PD5 goes back to the stopped motor, low
    drv.wr(sp, bytes([14, 0, 0]))
    drv.wait(2 * SERVO_FRAME + 8192)
    t1 = drv.now()
    drv.wait(3 * SERVO_FRAME)
    assert drv.edges("D5", t1) == []
    assert drv.pin("D5") == (0, "out")
    drv.wr(reg(drv, 0), b"\x80")                                 # motor 1 may run again
    check_state(drv, 0x80, 0x80, 0, 0)


@pytest.mark.parametrize("pwm", [255, 0x80])
def test_servo_14_off_then_motor_1_at_once_keeps_the_motor_line(drv, pwm):
    """Servo 14 turned off gives PD5 back to motor 1 at once (a PWM for it
    is taken by the very next request), so the servo's old schedule, which
    the interrupt runs until the frame a plan without channel 14 starts,
    must not write PD5 any more: its fall pulled motor 1's steady high
    (PWM 255 is the port's level, the compare output off) low for good,
    and its rise put a 1.5 ms high into a PWM of 0x80 (read back: 1, the
    motor kept its register value). Every instant of the frame is tried
    by writing right after the servo's rise (the fall still to come) and
    right after its fall (the next frame's pulse still to come). The two
    requests go on the gateway's line back to back at a chosen cycle
    (`rx`), the servo's line ending there: a loaded machine may let the
    simulator run past a cycle chosen a few frames ahead, and then the
    next frame's is taken."""
    sp = drv.lay["servo"] + 1
    line = ("%s\n%s\n" % (drv.req("S AA %02X 0E 0000 P" % sp),
                           drv.req("S AA %02X %02X P" % (reg(drv, 0), pwm)))).encode()
    first = len(line.split(b"\n")[0]) + 1
    byte = 10 * F_CPU // 115200
    gateway = drv.sim.control                                  # its serial line
    for after in ("rise", "fall"):
        drv.wr(sp, bytes([14, 0x05, 0xDC]))                   # servo 14: 1500 us
        drv.wait(2 * SERVO_FRAME + 8192)
        for _ in range(20):
            rise = drv.edges("D5", drv.now() - SERVO_FRAME)[0][0]
            at = rise + (1000 if after == "rise" else 11059 + 1000) + 3 * SERVO_FRAME
            try:                                               # servo 14 off, motor 1 at once
                gateway.rx(at - first * byte, line)
                break
            except SimControlError as e:
                assert "is past" in str(e), e
        else:
            pytest.fail("the simulator ran past every cycle chosen")
        drv.wait(max(1, at - drv.now()) + 3 * SERVO_FRAME)
        assert [drv.gw.read_reply() for _ in range(2)] == ["SWAAAAP", "SWAAP"]
        since = drv.now()
        drv.wait(60 * PWM_PERIOD)
        check_pwm(drv, "D5", pwm, since)
        if pwm != 255:
            m = drv.measure("D5", since - 3 * SERVO_FRAME + 4 * PWM_PERIOD)
            assert m["high"][1] < PWM_PERIOD, (after, "a servo pulse on motor 1's line", m)
        drv.wr(reg(drv, 0), b"\x00")
