"""examples/robot.py on a simulated robot, run as a user runs it: a separate
program given the simulator's port. The robot: an M32-D gateway with an
MPU-6050 at D0, an HMC5883L at 3C and an SRF08 at E0. What the sensors sense
is set through the control socket (`sense`); after N steps the steering
servo's width and the motors' PWM duties are measured on the pins (control
`measure`, in simulated cycles) and read back from the board, each exactly
the value the program's control law gives for the sensors' readings (the
registers' codes by the datasheets' formulas, then the law, both written out
here from the example's docstring). Wrong arguments, a missing port and each
missing sensor end it with one line."""

import math
import os
import re
import signal
import subprocess
import sys

import pytest

from conftest import WIDTH_TOL, ROOT, SERVO_FRAME, raw, require_builds, us_to_cycles
from orfa import Board, Gateway
from orfa.sim import SimBoard

EXAMPLE = ROOT / "examples" / "robot.py"
PARTS = [("mpu6050", 0xD0), ("hmc5883l", 0x3C), ("srf08", 0xE0)]
IMU, COMPASS, RANGER = 0xD0, 0x3C, 0xE0
G = 9.80665
STEPS = 3
PWM_PERIOD = 368                  # the motors' PWM (test_drv_motor.py)
SERVO_PIN, PWM_PINS, DIR_PINS = "A0", ("D5", "D4"), ("B0", "B1")


def robot(*args, timeout=120):
    """Run examples/robot.py ARGS; (exit status, stdout lines, stderr)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "host"))
    r = subprocess.run([sys.executable, str(EXAMPLE)] + [str(a) for a in args],
                       capture_output=True, text=True, timeout=timeout, env=env)
    return r.returncode, r.stdout.splitlines(), r.stderr


# --- the law, from the example's docstring, on the codes the parts report ----------

def readings(facing, field_ut, gyro_z, range_mm, accel):
    """What the program reads: the compass heading from the HMC5883L's codes
    at gain 1090 LSB/gauss, the gyro's Z at +-500 degrees/s (65.5 LSB per
    degree/s, Adafruit's setting) and the accelerometer at +-2 g (16384
    LSB/g), the SRF08's range in cm (0: nothing within its 2021 mm)."""
    rad = math.radians(facing)
    x = raw(field_ut * math.cos(rad) / 100, 1090, -2048, 2047)
    y = raw(field_ut * math.sin(rad) / 100, 1090, -2048, 2047)
    heading = math.degrees(math.atan2(y, x)) % 360
    turn = -raw(gyro_z, 65.5) / 65.5
    accel = [raw(a / G, 16384) / 16384 * G for a in accel]
    cm = 0 if range_mm > 47 * 43 else math.floor(range_mm / 10 + 0.5)
    return heading, turn, cm, accel


def law(target, heading, turn, cm, accel):
    """(servo width us, left duty, right duty)."""
    error = (target - heading + 180) % 360 - 180
    steer = max(-30.0, min(30.0, 0.5 * error - 0.1 * turn))
    g = math.sqrt(sum(a * a for a in accel))
    up = g >= G / 2 and accel[2] >= g * math.cos(math.radians(30))
    if not up or 0 < cm <= 25:
        speed = 0.0
    elif cm == 0 or cm >= 100:
        speed = 180.0
    else:
        speed = 180 * (cm - 25) / 75
    width = round(1000 + 1000 * (steer + 75) / 150)
    return width, round(speed * (1 + steer / 100)), round(speed * (1 - steer / 100))


# (name, target heading, facing, field uT, gyro Z deg/s, range mm, accel m/s^2, want)
# `want` is what the law gives, worked by hand, to check the law's code here.
SCENES = [
    ("hard left, a wall ahead", 0, 60, 20, 0, 800, (0, 0, G), (1300, 92, 172)),
    ("right, damped, way clear", 40, 21, 25, -30, 3000, (0.5, -0.3, G), (1543, 192, 168)),
    ("too close to go", 90, 80, 48, 0, 200, (0, 0, G), (1533, 0, 0)),
    ("tipped over", 300, 331, 30, 12.5, 1500, (0, 6.0, 7.0), (1405, 0, 0)),
    ("a little left, slowing", 180, 187.5, 35, 4, 450, (-1.0, 0.8, 9.6), (1478, 46, 50)),
]


@pytest.mark.parametrize("scene", SCENES, ids=[s[0] for s in SCENES])
def test_law_of_the_scenes(scene):
    _, target, facing, field, gyro_z, mm, accel, want = scene
    assert law(target, *readings(facing, field, gyro_z, mm, accel)) == want


# --- the program on the simulated robot -------------------------------------------

@pytest.fixture(scope="module")
def sim():
    require_builds(["m32d"])
    s = SimBoard("m32d", parts=PARTS, control=True, trace=False)
    s.start()
    try:
        yield s
    finally:
        assert s.stop() == 0, s.final_stderr


def measure_outputs(sim):
    """Let the last widths start (they take the next frame), then measure
    five frames: (servo high (min, max), {pin: high (min, max) or steady}),
    DIR levels."""
    c = sim.control
    c.wait(2 * SERVO_FRAME + 8192)
    since = c.time()
    c.wait(5 * SERVO_FRAME)
    servo = c.measure(SERVO_PIN, since=since)
    pwm = {pin: c.measure(pin, since=since) for pin in PWM_PINS}
    dirs = [c.pin(pin) for pin in DIR_PINS]
    return servo, pwm, dirs


@pytest.mark.parametrize("scene", SCENES, ids=[s[0] for s in SCENES])
def test_robot_steers_by_its_sensors(sim, scene):
    _, target, facing, field, gyro_z, mm, accel, want = scene
    c = sim.control
    rad = math.radians(facing)
    c.sense(IMU, "accel", *accel)
    c.sense(IMU, "gyro", 0, 0, gyro_z)
    c.sense(COMPASS, "field", field * math.cos(rad), field * math.sin(rad), -30)
    c.sense(RANGER, "range", mm)
    status, out, err = robot("--port", sim.port, "--heading", target, "--iterations", STEPS)
    assert status == 0 and err == "", err
    width, left, right = want
    heading, turn, cm, _ = readings(facing, field, gyro_z, mm, accel)
    assert len(out) == STEPS, out
    for n, line in enumerate(out, 1):          # every step saw the same world
        assert line.startswith("%3d heading %5.1f turn %+6.1f deg/s range %3d cm "
                               % (n, heading, turn, cm)), line
        assert line.endswith("(%d us) motors %d %d" % (width, left, right)), line

    servo, pwm, dirs = measure_outputs(sim)
    assert "high" in servo and servo["n"] >= 4, servo
    for high in servo["high"][:2]:
        assert abs(high - us_to_cycles(width)) <= WIDTH_TOL, (servo, width)
    assert abs(servo["period"][2] - SERVO_FRAME) <= 147, servo
    for pin, duty in zip(PWM_PINS, (left, right)):
        m = pwm[pin]
        if duty == 0:
            assert m == {"steady": 0}, (pin, m)
            continue
        assert m["period"][:2] == (PWM_PERIOD, PWM_PERIOD), (pin, m)
        for high in m["high"][:2]:
            # docs: duty = PWM/255 within 1/368
            assert abs(high / PWM_PERIOD - duty / 255) <= 1 / PWM_PERIOD, (pin, duty, m)
    assert dirs == [(0, "out"), (0, "out")]                 # forward
    with Gateway(sim.port) as gw:                           # and exactly, from the board
        board = Board(gw)
        assert board.servo.width(0) == width
        assert board.motor.duties() == [left, right]


def test_ctrl_c_stops_the_motors(sim):
    """Without --iterations it runs until Ctrl-C (SIGINT), which stops the
    motors: exit status 130, one line, both duties 0 on the board."""
    c = sim.control
    c.sense(IMU, "accel", 0, 0, G)
    c.sense(IMU, "gyro", 0, 0, 0)
    c.sense(COMPASS, "field", 20, 0, 0)
    c.sense(RANGER, "range", 3000)
    env = dict(os.environ, PYTHONPATH=str(ROOT / "host"))
    proc = subprocess.Popen([sys.executable, str(EXAMPLE), "--port", sim.port],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        first = proc.stdout.readline()              # a step done: the motors run
        assert first.endswith("(1500 us) motors 180 180\n"), first
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert (proc.returncode, err) == (130, "robot: stopped (Ctrl-C)\n")
    with Gateway(sim.port) as gw:
        assert Board(gw).motor.duties() == [0, 0]


def test_sim_option_runs_the_same_program():
    """--sim: the program starts its own simulated robot (upright, facing
    60 degrees in 20 microtesla, a wall at 80 cm) and runs on it; it prints
    what docs/sensors.md shows, the law's values."""
    require_builds(["m32d"])
    status, out, err = robot("--sim", "--iterations", 3)
    assert status == 0 and err == "", err
    heading, turn, cm, _ = readings(60, 20, 0, 800, (0, 0, G))
    assert out == ["%3d heading %5.1f turn %+6.1f deg/s range %3d cm upright -> steer -30.0 deg"
                   " (1300 us) motors 92 172" % (n, heading, turn, cm) for n in (1, 2, 3)]
    docs = (ROOT / "docs" / "sensors.md").read_text()
    shown = re.search(r"\n    \$ python3 examples/robot.py --sim --iterations 3\n((?:    .*\n)+)",
                      docs)
    assert shown and [line[4:] for line in shown.group(1).splitlines()] == out


@pytest.mark.parametrize("parts, message", [
    ([], "robot: no MPU-6050 IMU at 0x68 (ORFA D0): No I2C device at address: 0x68"),
    (PARTS[:1], "robot: no HMC5883L compass at 0x1E (ORFA 3C): [Errno 6] No such device or"
                " address: read_i2c_block_data at 0x1E: no ACK for the address (ORFA ERROR 06:"
                " no such device, or the bus could not be had)"),
    (PARTS[:2], "robot: no SRF08 ranger at 0x70 (ORFA E0): [Errno 6] No such device or"
                " address: write_byte_data at 0x70: no ACK for the address (ORFA ERROR 06:"
                " no such device, or the bus could not be had)"),
], ids=["no IMU", "no compass", "no ranger"])
def test_a_missing_sensor_is_one_line(parts, message):
    require_builds(["m32d"])
    with SimBoard("m32d", parts=parts, trace=False) as s:
        status, out, err = robot("--port", s.port, "--iterations", 1)
    assert (status, out, err) == (1, [], message + "\n")


@pytest.mark.parametrize("args, message", [
    (["--iterations", "1"], "one of the arguments --port --sim is required"),
    (["--sim", "--iterations", "0"], "argument --iterations: '0': a number of steps, 1 or more"),
    (["--sim", "--heading", "360"], "argument --heading: '360': a heading in degrees,"
                                    " 0 to under 360"),
    (["--sim", "--heading", "nan"], "argument --heading: 'nan': a heading in degrees,"
                                    " 0 to under 360"),
    (["--sim", "--port", "x"], "argument --port: not allowed with argument --sim"),
])
def test_wrong_arguments(args, message):
    status, out, err = robot(*args)
    assert status == 2 and out == [], err
    assert err.splitlines()[-1] == "robot.py: error: " + message


def test_a_port_that_does_not_open(tmp_path):
    status, out, err = robot("--port", tmp_path / "tty", "--iterations", 1)
    assert (status, out) == (1, [])
    assert err == "robot: cannot open %s: [Errno 2] No such file or directory\n" % (tmp_path / "tty")
