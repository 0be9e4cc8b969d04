#!/usr/bin/env python3
"""A robot control loop at the serial line's speed: each step sets 16 servo
widths and, on an M32-D, both motors, reads the 8 ADC channels and an
MPU-6050's 14-byte burst (accelerometer, temperature, gyroscope).

    python3 examples/control_loop.py --port /dev/ttyUSB0 [--baud 460800] [--steps N]
    python3 examples/control_loop.py --sim [--board m128s] [--baud 230400] [--steps N]
    ... [--one-at-a-time]

The board is the gateway itself (its own servo, motor and ADC drivers), the
IMU on its I2C bus at D0 (7-bit 0x68). Each step is four requests:

  SAA<SP><16 triples>P     servo widths (on an M32-D the channels whose pins
                           the ADC inputs and the motors' PWM lines hold are
                           written 0: off; see free_servo_channels)
  SAA<PWM1>aabbccddP       both motors, one write (M32-D)
  SAA<RD>SAB10P            the 8 ADC results, 10 bits each
  SD03BSD10EP              the IMU's 14 bytes from ACCEL_XOUT_H

Pipelined (the default), the next AHEAD (2) steps' requests are submitted
before a step's replies are waited for (Board.submit,
Gateway.submit_transactions: the library keeps the flow rule), so the line
never waits for the PC between steps; the outputs are computed from the
newest inputs in hand, AHEAD steps older than a loop that waits.
--one-at-a-time sends the same requests as naive code does, each after the
last one's reply.

The law here is a demonstration: each servo follows an ADC input (0..5 V
to 1000..2000 us) plus a slow sweep, the motors the IMU's tilt. Every reply
is checked: a refused write raises, a read of the wrong length raises.

Prints steps per second and the Python process's CPU time per step. With
--sim the simulator runs at real time (orfa-sim --real-time), so the PC has
a real board's time per byte. Exit status 0, 1 with one line on stderr, 2
for wrong arguments.
"""

import argparse
import importlib.util
import sys
import time
from collections import deque
from pathlib import Path

if importlib.util.find_spec("orfa") is None:      # run from the repository, not installed
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "host"))

from orfa import Board, Gateway, OrfaError  # noqa: E402
from orfa import protocol as p  # noqa: E402

IMU = 0xD0                     # MPU-6050, 8-bit address (AD0 low)
PWR_MGMT_1, ACCEL_XOUT_H, BURST = 0x6B, 0x3B, 14
G = 9.80665
#: the MPU-6050's scales at its reset ranges (+-2 g, +-250 degrees/s)
ACCEL_LSB_PER_G, GYRO_LSB_PER_DPS, TEMP_LSB_PER_C, TEMP_OFFSET_C = 16384.0, 131.0, 340.0, 36.53
SERVOS = 16                    # the first 16 channels (the M128-S has 32)
ADC_CHANNELS = 8
ADC_VREF, ADC_FULL = 5.0, 1024  # AVCC, 10 bits
I2C_KHZ = 400                  # the MPU-6050's fast mode
#: steps submitted before the oldest is waited for (run)
AHEAD = 2


def decode_imu(data):
    """The 14 bytes from ACCEL_XOUT_H as ((ax, ay, az) m/s^2, temp degrees C,
    (gx, gy, gz) degrees/s)."""
    if len(data) != BURST:
        raise ValueError("an MPU-6050 burst is %d bytes, not %d" % (BURST, len(data)))
    w = [int.from_bytes(data[i:i + 2], "big", signed=True) for i in range(0, BURST, 2)]
    accel = tuple(v / ACCEL_LSB_PER_G * G for v in w[0:3])
    gyro = tuple(v / GYRO_LSB_PER_DPS for v in w[4:7])
    return accel, w[3] / TEMP_LSB_PER_C + TEMP_OFFSET_C, gyro


def free_servo_channels(board):
    """The first SERVOS channels, and which of them may pulse: not on the
    ADC port (the inputs read here) nor on a motor's PWM line (the M32-D's
    channels 0-7 are PA0-PA7, its 14 and 15 the PWM lines: a pin has one
    function at a time). From the board map."""
    bmap = board.board_map("servo")
    taken = {(q.port, q.bit) for q in bmap.pins_of("MOTOR_PWM")} if board.has("motor") else set()
    free = []
    for ch in range(SERVOS):
        pins = bmap.pins_of("SERVO", ch)
        if not any(q.port == bmap.adc_port or (q.port, q.bit) in taken for q in pins):
            free.append(ch)
    return free


class Step:
    """One step's requests under way; wait() gives its inputs."""

    def __init__(self, parts):
        self.parts = parts

    def wire(self):
        """(characters sent, characters received) of the step, terminators
        included (once it is waited for)."""
        outputs, adc, imu = self.parts
        pendings = [o.pending for o in outputs] + [adc.pending, imu]
        return (sum(len(line) + 1 for q in pendings for line in q.lines),
                sum(len(reply) + 2 for q in pendings for reply in q.replies))

    def wait(self):
        """(the 8 ADC results, raw 0..1023; the IMU's 14 bytes), after every
        write of the step was acknowledged (a refusal raises)."""
        outputs, adc, imu = self.parts
        for pending in outputs:
            pending.wait()
        (rd,), = adc.wait()
        return inputs_of(rd, imu.wait()[0])


def inputs_of(rd, imu_result):
    """(ADC results, IMU bytes) from the RD read and the IMU transaction's
    result (an OrfaError raises)."""
    if isinstance(imu_result, OrfaError):
        raise imu_result
    return [rd[i] << 8 | rd[i + 1] for i in range(0, 2 * ADC_CHANNELS, 2)], imu_result[1].data


class ControlLoop:
    """The loop's requests on one board (the gateway's own drivers)."""

    def __init__(self, board):
        self.board = board
        self.gateway = board.gateway
        self.motors = board.has("motor")
        self.free = free_servo_channels(board)
        #: the newest inputs (run), and the last step submitted (submit)
        self.latest = None
        self.last = None

    def setup(self):
        """ADC channels on (AVCC, 10 bits), the IMU awake, the bus at 400 kHz."""
        self.board.adc.configure(range(ADC_CHANNELS), "avcc", 10)
        self.gateway.clock(I2C_KHZ)
        self.gateway.write_register(IMU, PWR_MGMT_1, [0x00])

    def _outputs(self, widths, duties):
        b = self.board
        triples = b"".join(bytes([ch, widths.get(ch, 0) >> 8, widths.get(ch, 0) & 0xFF])
                           for ch in range(SERVOS))
        ops = [[b.op_write("servo", "SP", triples)]]
        if self.motors:
            ops.append([b.op_write("motor", "PWM1", [abs(d) for d in duties]
                                   + [1 if d < 0 else 0 for d in duties])])
        return ops

    def _inputs(self):
        return ([[self.board.op_read("adc", "RD", 2 * ADC_CHANNELS)]],
                [[p.Write(IMU, bytes([ACCEL_XOUT_H])), p.Read(IMU, BURST)]])

    def submit(self, widths, duties):
        """Submit one step (widths {channel: us}, duties (left, right)):
        its requests go out as the flow rule lets them; a Step."""
        b = self.board
        adc, imu = self._inputs()
        self.last = Step(([b.submit([group]) for group in self._outputs(widths, duties)],
                          b.submit(adc), self.gateway.submit_transactions(imu)))
        return self.last

    def step_one_at_a_time(self, widths, duties):
        """The same requests, each sent after the last one's reply; the inputs."""
        b = self.board
        for group in self._outputs(widths, duties):
            b.execute([group])
        adc, imu = self._inputs()
        (rd,), = b.execute(adc)
        return inputs_of(rd, self.gateway.transactions(imu)[0])


def law(loop, k, inputs):
    """A demonstration law: (servo widths, motor duties) for step k from
    the newest inputs (None before the first): each free servo follows an
    ADC input plus a sweep, the motors the IMU's tilt."""
    raw, imu = inputs if inputs is not None else ([0] * ADC_CHANNELS, bytes(BURST))
    (ax, ay, _), _, _ = decode_imu(imu)
    sweep = k % 100
    widths = {ch: 1000 + raw[ch % ADC_CHANNELS] * 1000 // ADC_FULL + sweep for ch in loop.free}
    duty = lambda a: max(-255, min(255, round(a / G * 255)))     # noqa: E731
    return widths, ((duty(ax + ay), duty(ax - ay)) if loop.motors else ())


def run(loop, steps, pipelined=True, inputs_seen=None, ahead=AHEAD):
    """Run `steps` steps of `law`; each step's inputs go to inputs_seen(k,
    inputs) if given (a check). Pipelined: `ahead` steps are submitted
    before the oldest one's replies are waited for, so the requests of the
    next steps wait in the gateway, ready to go out as soon as the flow
    rule lets them; each step's outputs come from the newest inputs in
    hand (`ahead` steps old)."""
    latest = None
    if not pipelined:
        for k in range(steps):
            latest = loop.step_one_at_a_time(*law(loop, k, latest))
            if inputs_seen:
                inputs_seen(k, latest)
        loop.latest = latest
        return latest
    under_way = deque()
    for k in range(steps):
        under_way.append(loop.submit(*law(loop, k, latest)))
        if len(under_way) > ahead:
            latest = under_way.popleft().wait()
            if inputs_seen:
                inputs_seen(k - ahead, latest)
    while under_way:
        latest = under_way.popleft().wait()
        if inputs_seen:
            inputs_seen(steps - len(under_way) - 1, latest)
    loop.latest = latest
    return latest


def timed(loop, steps, pipelined=True, clock=time.monotonic, inputs_seen=None, warmup=0):
    """run() timed from the inputs of step `warmup` - 1 (from the start if
    0: the pipeline still empty) to the last step's: (the clock's ticks,
    the Python process's CPU seconds) of the steps - warmup steps in
    between. `clock` is wall time by default; a simulator's cycle counter
    (SimControl.time) gives the board's own time."""
    marks = []

    def seen(k, inputs):
        if inputs_seen:
            inputs_seen(k, inputs)
        if k == warmup - 1 or k == steps - 1:
            marks.append((clock(), time.process_time()))

    if not warmup:
        marks.append((clock(), time.process_time()))
    run(loop, steps, pipelined, seen)
    (t0, cpu0), (t1, cpu1) = marks
    return t1 - t0, cpu1 - cpu0


#: What the simulated board of --sim senses: 1.0 .. 4.5 V on the ADC
#: inputs, the IMU tilted a little, turning, at 25 degrees C.
SIM_ADC_MV = {ch: 1000 + 500 * ch for ch in range(ADC_CHANNELS)}
SIM_SENSE = {"accel": (1.0, -2.0, G), "temp": (25.0,), "gyro": (10.0, -20.0, 30.0)}


def simulated_board(board, baud, firmware=None):
    """A simulated board running at real time (orfa-sim --real-time) at
    `baud` (the gateway build for it, or `firmware`), sensing SIM_ADC_MV
    and SIM_SENSE; started, the IMU's registers holding the values."""
    from orfa.sim import SimBoard
    sim = SimBoard(board, parts=[("mpu6050", IMU)], control=True, trace=False,
                   adc=SIM_ADC_MV, firmware=firmware or firmware_at(board, baud),
                   extra_args=["--real-time"]).start()
    for quantity, values in SIM_SENSE.items():
        sim.control.sense(IMU, quantity, *values)
    return sim


def check_sim_inputs(k, inputs):
    """Step k's inputs are what the simulated board senses (SIM_*), to the
    ADC's and the IMU's resolution; ValueError with one line if not."""
    raw, imu = inputs
    for ch, mv in SIM_ADC_MV.items():
        want = mv / 1000.0 / ADC_VREF * ADC_FULL
        if abs(raw[ch] - want) > 2:
            raise ValueError("step %d: ADC channel %d read %d, the %d mV it senses is %.1f"
                             % (k, ch, raw[ch], mv, want))
    accel, temp, gyro = decode_imu(imu)
    got = {"accel": accel, "temp": (temp,), "gyro": gyro}
    lsb = {"accel": G / ACCEL_LSB_PER_G, "temp": 1 / TEMP_LSB_PER_C, "gyro": 1 / GYRO_LSB_PER_DPS}
    for quantity, values in SIM_SENSE.items():
        if any(abs(a - b) > lsb[quantity] for a, b in zip(got[quantity], values)):
            raise ValueError("step %d: the IMU's %s read %r, it senses %r (burst %s)"
                             % (k, quantity, got[quantity], values, imu.hex()))


def firmware_at(board, baud):
    """The gateway build for `baud` (orfa.locate.gateway_firmware: the
    default one at 115200, else build/<board>-gate-<baud>, made with `make
    BAUD=...` when missing or out of date); ValueError if none."""
    from orfa.locate import gateway_firmware
    return gateway_firmware(board, baud)


def report(loop, steps, pipelined, check):
    """Run the loop `steps` steps and print its rate and its last inputs."""
    loop.setup()
    wall, cpu = timed(loop, steps, pipelined, inputs_seen=check)
    accel, temp, gyro = decode_imu(loop.latest[1])
    print("%d steps in %.3f s: %.1f steps/s, Python %.3f ms CPU per step"
          % (steps, wall, steps / wall, cpu * 1e3 / steps))
    print("last inputs: ADC %s; accel %s m/s^2, %.1f C, gyro %s deg/s"
          % (loop.latest[0], " ".join("%.2f" % a for a in accel), temp,
             " ".join("%.1f" % w for w in gyro)))


def baud(text):
    """--baud: a whole number of baud above 0 (which rates a board runs,
    the board or its build says)."""
    try:
        rate = int(text, 10)
    except ValueError:
        rate = 0
    if rate <= 0:
        raise argparse.ArgumentTypeError("%r is not a serial rate: a whole number of baud"
                                         " above 0 (460800)" % text)
    return rate


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    where = ap.add_mutually_exclusive_group(required=True)
    where.add_argument("--port", metavar="PATH", help="the gateway's serial port (any pyserial URL)")
    where.add_argument("--sim", action="store_true", help="run on a simulated board")
    ap.add_argument("--board", choices=("m32d", "m128s"), default="m32d",
                    help="the simulated board (--sim; default m32d)")
    ap.add_argument("--baud", type=baud, default=p.DEFAULT_BAUD, help="serial rate (default 115200)")
    ap.add_argument("--steps", type=int, default=500, metavar="N", help="steps to run (default 500)")
    ap.add_argument("--one-at-a-time", action="store_true",
                    help="each request after the last one's reply (as naive code does)")
    args = ap.parse_args(argv)
    if args.steps < 1:
        ap.error("--steps: 1 or more")
    sim = None
    try:
        sim = simulated_board(args.board, args.baud) if args.sim else None
        with Gateway(sim.port if sim else args.port, baudrate=args.baud) as gw:
            report(ControlLoop(Board(gw)), args.steps, not args.one_at_a_time,
                   check_sim_inputs if sim else None)
        status = 0
    except (OrfaError, OSError, ValueError) as e:
        print("control_loop: %s" % e, file=sys.stderr)
        status = 1
    if sim is not None:
        sim.stop()
    return status

if __name__ == "__main__":
    sys.exit(main())
