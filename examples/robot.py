#!/usr/bin/env python3
"""A small robot program: steer towards a compass heading, slow down for
obstacles, stop when tipped over.

    python3 examples/robot.py --port /dev/ttyUSB0 [--heading DEG] [--iterations N]
    python3 examples/robot.py --sim [--heading DEG] [--iterations N]

The robot: an OR-AVR-M32-D gateway with a steering servo on channel 0 and
two drive motors (1 left, 2 right), and on its I2C bus an MPU-6050 IMU (D0,
7-bit 0x68), an HMC5883L compass (3C, 0x1E) and an SRF08 ranger (E0, 0x70).
The sensors are read by the Python world's own means over the gateway: the
IMU by Adafruit's `adafruit_mpu6050` on `orfa.busio.I2C`, the compass and
the ranger through `orfa.smbus.SMBus`; the servo and the motors through
`orfa.Board`. All of them share one `orfa.Gateway`.

--port opens a real gateway's serial port; --sim starts a simulated robot
with these sensors (upright, facing 60 degrees, an obstacle 80 cm ahead)
and runs the same program on it. Nothing else differs.

Each step (docs/sensors.md, "A robot program"):

  heading  = atan2(Y, X) of the compass, degrees 0..360 (its X axis forward)
  error    = the target heading minus heading, wrapped into -180..180
             (-180 included, 180 not)
  turn     = -gyro Z in degrees/s (the heading's rate: Z points up)
  steer    = KP * error - KD * turn, clamped to +-MAX_STEER degrees;
             the steering servo at that angle (ServoRange(): +-75 degrees
             at 1000..2000 us, so 1500 + steer * 20 / 3 us, rounded)
  speed    = 0 at STOP_CM or nearer, CRUISE with nothing within SLOW_CM (or
             no echo), in proportion between; 0 when not upright (gravity
             more than TILT_MAX degrees off the IMU's Z axis, or under half
             a g: falling, or no IMU reading)
  motors   = left round(speed * (1 + steer / DIFF)), right
             round(speed * (1 - steer / DIFF)): the outer wheel faster

With --iterations N the program takes N steps and leaves the servo and the
motors as the last step set them (to be looked at: `orfa motor`, the
simulator's pins); without it, it runs until Ctrl-C, which stops the motors.
Exit status 0, 1 with one line on stderr (no port, a sensor missing, the
ranger never answering), 2 for wrong arguments, 130 after Ctrl-C.
"""

import argparse
import importlib.util
import math
import sys
import time
from pathlib import Path

if importlib.util.find_spec("orfa") is None:      # run from the repository, not installed
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "host"))

from orfa import Board, Gateway, OrfaError, ServoRange  # noqa: E402
from orfa.busio import I2C  # noqa: E402
from orfa.smbus import SMBus  # noqa: E402

# --- the control law ---------------------------------------------------------
KP = 0.5                  # degrees of steering per degree of heading error
KD = 0.1                  # degrees of steering per degree/s of turning
MAX_STEER = 30.0          # degrees either way
STOP_CM, SLOW_CM = 25, 100
CRUISE = 180              # motor duty (of 255) with the way clear
DIFF = 100.0              # steering degrees at which the inner wheel would stop
TILT_MAX = 30.0           # degrees
G = 9.80665

# --- the robot ----------------------------------------------------------------
STEER_CHANNEL = 0
STEERING = ServoRange()   # +-75 degrees at 1000..2000 us
IMU, COMPASS, RANGER = 0x68, 0x1E, 0x70      # 7-bit addresses
RANGE_CM = 0x51           # SRF08 command: range in cm
#: SRF08 range register: the farthest echo (R + 1) x 43 mm, here 2021 mm;
#: a ranging then takes 65 ms x (R + 1) / 256, about 12 ms
RANGE_REGISTER = 46
RANGER_WAIT_S = 0.5       # a ranging that takes longer is a fault
HMC5883L_ID = b"H43"
COMPASS_WAIT_S = 0.5      # it measures every 13 ms
HMC5883L_OVERFLOW = -4096

#: The simulated robot of --sim (the IMU and the compass as `make demo-robot`
#: has them, and the ranger) and what it senses: upright, facing 60 degrees in a 20 microtesla field, a wall
#: 80 cm ahead.
SIM_PARTS = [("mpu6050", IMU << 1), ("hmc5883l", COMPASS << 1), ("srf08", RANGER << 1)]
SIM_FACING, SIM_FIELD_UT, SIM_OBSTACLE_MM = 60.0, 20.0, 800


def wrap(degrees):
    """An angle into -180..180 (-180 included, 180 not)."""
    return (degrees + 180.0) % 360.0 - 180.0


def upright(accel):
    """Gravity within TILT_MAX of the IMU's Z axis, and at least half a g."""
    ax, ay, az = accel
    g = math.sqrt(ax * ax + ay * ay + az * az)
    return g >= G / 2 and az >= g * math.cos(math.radians(TILT_MAX))


def control(target, heading, turn, range_cm, accel):
    """One step of the law: (steering degrees, left duty, right duty).
    heading None: no compass reading (steer straight); range_cm 0: no echo."""
    steer = 0.0 if heading is None else KP * wrap(target - heading) - KD * turn
    steer = max(-MAX_STEER, min(MAX_STEER, steer))
    if not upright(accel) or 0 < range_cm <= STOP_CM:
        speed = 0.0
    elif range_cm == 0 or range_cm >= SLOW_CM:
        speed = float(CRUISE)
    else:
        speed = CRUISE * (range_cm - STOP_CM) / (SLOW_CM - STOP_CM)
    return steer, round(speed * (1 + steer / DIFF)), round(speed * (1 - steer / DIFF))


# --- the sensors ----------------------------------------------------------------
def signed16(hi, lo):
    value = hi << 8 | lo
    return value - 0x10000 if value & 0x8000 else value


class Fault(Exception):
    """A sensor that is missing or does not behave: the program stops."""


class Compass:
    """HMC5883L through smbus: continuous measurement at 75 Hz, gain 1090
    LSB/gauss (its datasheet's registers)."""

    def __init__(self, bus):
        self.bus = bus
        try:
            ident = bytes(bus.read_i2c_block_data(COMPASS, 0x0A, 3))
        except OSError as e:
            raise Fault("no HMC5883L compass at 0x%02X (ORFA 3C): %s" % (COMPASS, e)) from None
        if ident != HMC5883L_ID:
            raise Fault("the device at 0x%02X is no HMC5883L (identification %r)"
                        % (COMPASS, ident))
        bus.write_i2c_block_data(COMPASS, 0x00, [0x18, 0x20, 0x00])   # CRA, CRB, mode

    def heading(self):
        """Degrees 0..360 from the next measurement (status RDY), or None
        when an axis overflows."""
        since = time.monotonic()
        while not self.bus.read_byte_data(COMPASS, 0x09) & 0x01:
            if time.monotonic() - since > COMPASS_WAIT_S:
                raise Fault("the HMC5883L at 0x%02X has measured nothing for %g s"
                            % (COMPASS, COMPASS_WAIT_S))
            time.sleep(0.002)
        d = self.bus.read_i2c_block_data(COMPASS, 0x03, 6)            # X, Z, Y
        x, y = signed16(d[0], d[1]), signed16(d[4], d[5])
        if HMC5883L_OVERFLOW in (x, y):
            return None
        return math.degrees(math.atan2(y, x)) % 360.0


class Ranger:
    """SRF08 through smbus: a ranging started, its result taken later (the
    ranger does not answer the bus while it ranges)."""

    def __init__(self, bus):
        self.bus = bus
        try:
            bus.write_byte_data(RANGER, 0x02, RANGE_REGISTER)
        except OSError as e:
            raise Fault("no SRF08 ranger at 0x%02X (ORFA E0): %s" % (RANGER, e)) from None

    def start(self):
        self.bus.write_byte_data(RANGER, 0x00, RANGE_CM)
        self.started = time.monotonic()

    def result_cm(self):
        """The first echo in cm (0: none), once the ranging is done."""
        while True:
            try:
                d = self.bus.read_i2c_block_data(RANGER, 0x02, 2)
                return d[0] << 8 | d[1]
            except OSError:
                if time.monotonic() - self.started > RANGER_WAIT_S:
                    raise Fault("the SRF08 at 0x%02X has not answered for %g s after"
                                " a ranging" % (RANGER, RANGER_WAIT_S)) from None
                time.sleep(0.002)


def imu_of(i2c):
    try:
        import adafruit_mpu6050
    except ImportError:
        raise Fault("this program reads its IMU with Adafruit's adafruit_mpu6050: pip install"
                    " it (docs/sensors.md, \"Installing the drivers\")") from None
    try:
        return adafruit_mpu6050.MPU6050(i2c)
    except (OSError, ValueError, RuntimeError) as e:
        raise Fault("no MPU-6050 IMU at 0x%02X (ORFA D0): %s" % (IMU, e)) from None


# --- the program ------------------------------------------------------------------
def run(gw, target, iterations, out=sys.stdout):
    i2c, bus, board = I2C(gw), SMBus(gw), Board(gw)     # the driver locks the I2C itself
    imu, compass, ranger = imu_of(i2c), Compass(bus), Ranger(bus)
    step = 0
    try:
        while iterations is None or step < iterations:
            ranger.start()                         # it ranges while the others are read
            heading = compass.heading()
            accel = imu.acceleration
            turn = 0.0 - math.degrees(imu.gyro[2])         # no -0.0
            range_cm = ranger.result_cm()
            steer, left, right = control(target, heading, turn, range_cm, accel)
            board.servo.set_angle(STEER_CHANNEL, steer, STEERING)
            board.motor.set_all(left, right)
            step += 1
            print("%3d heading %s turn %+6.1f deg/s range %3d cm %s -> steer %+5.1f deg"
                  " (%d us) motors %d %d"
                  % (step, " none" if heading is None else "%5.1f" % heading, turn, range_cm,
                     "upright" if upright(accel) else "TIPPED ", steer,
                     STEERING.width(steer), left, right), file=out, flush=True)
    except BaseException:                          # Ctrl-C, a fault: the robot stops
        try:
            board.motor.set_all(0, 0)
        except (OrfaError, OSError):
            pass            # the line itself failed: the board's failsafe is the last guard
        raise


def simulated_robot():
    """The robot of --sim, started, sensing its world (see SIM_*)."""
    from orfa.sim import SimBoard
    sim = SimBoard("m32d", parts=SIM_PARTS, control=True, trace=False).start()
    c = sim.control
    c.sense(IMU << 1, "accel", 0, 0, G)
    rad = math.radians(SIM_FACING)
    c.sense(COMPASS << 1, "field", SIM_FIELD_UT * math.cos(rad), SIM_FIELD_UT * math.sin(rad), 0)
    c.sense(RANGER << 1, "range", SIM_OBSTACLE_MM)
    return sim


def positive(text):
    try:
        value = int(text, 10)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError("%r: a number of steps, 1 or more" % text)
    return value


def heading_arg(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 <= value < 360:
        raise argparse.ArgumentTypeError("%r: a heading in degrees, 0 to under 360" % text)
    return value


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    where = ap.add_mutually_exclusive_group(required=True)
    where.add_argument("--port", metavar="PATH", help="the gateway's serial port (any pyserial URL)")
    where.add_argument("--sim", action="store_true", help="start a simulated robot and run on it")
    ap.add_argument("--heading", type=heading_arg, default=0.0, metavar="DEG",
                    help="the heading to hold, degrees from magnetic north (default 0)")
    ap.add_argument("--iterations", type=positive, metavar="N",
                    help="take N steps, then leave the outputs as they are (default: until Ctrl-C)")
    args = ap.parse_args(argv)
    sim = None
    try:
        if args.sim:
            sim = simulated_robot()
            port = sim.port
        else:
            port = args.port
        with Gateway(port) as gw:
            run(gw, args.heading, args.iterations)
    except (Fault, OrfaError, OSError) as e:
        print("robot: %s" % e, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("robot: stopped (Ctrl-C)", file=sys.stderr)
        return 130
    finally:
        if sim is not None:
            sim.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
