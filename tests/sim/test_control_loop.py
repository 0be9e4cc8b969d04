"""examples/control_loop.py on simulated boards at every rate from 115200 up
(issue 20): the loop's replies are right (writes acknowledged, the ADC and
the IMU read what the simulator senses, the servos and motors left as the
last step set them), pipelined and one request at a time, and the pipelined
loop keeps the line busy: 95 % of the wire for its own characters or more,
in simulated time, the simulator at real time (orfa-sim --real-time) so the
PC has a real board's time per byte.

Where the target is missed the board's CPU is what limits, not the line nor
the PC (docs/python.md, "Pipelining across calls"; tools/profile.py): at 460800 receiving,
parsing and answering the step's characters alone take longer than their
wire time on both boards; at 230400 the M32-D's work a step (its servo
write and cycle-exact edges) leaves it at about 93 %, the flow window's
round trips the rest. Those rows still must reach FLOOR (a little under
what make bench measures), so a slower firmware fails them; reaching 95 %
there is an expected failure (xfail), not a pass.
"""

import sys

import pytest

from conftest import ROOT, build_gateway, require_builds
from orfa import Board
from orfa.gateway import Gateway
from orfa.protocol import DEFAULT_BAUD, F_CPU

sys.path.insert(0, str(ROOT / "examples"))
import control_loop as cl  # noqa: E402

RATES = (115200, 230400, 460800)
STEPS, STEPS_ONE = 40, 8
#: steps before the pipelined loop is timed: the line full
WARMUP = 5
TRIES = 3
TARGET = 95.0

#: the pipelined loop's least % of the wire on the rows that miss TARGET
#: (make bench: M32-D 93.0 at 230400 and 49.8 at 460800, M128-S 61.9 at
#: 460800; the simulator at real time on a busy machine gives a few % less),
#: and why they do: the board's CPU
FLOOR = {("m32d", 230400): 86.0, ("m32d", 460800): 44.0, ("m128s", 460800): 55.0}
CPU_BOUND = "the board's CPU a step is about the step's wire time or longer (docs/python.md)"

CORRECT = {}


def cases(marks):
    return [pytest.param(b, r, marks=marks.get((b, r), ())) for b in ("m32d", "m128s")
            for r in RATES]


@pytest.fixture
def loop_on(request):
    """A started simulated board at a rate with its ControlLoop set up."""
    opened = []

    def start(board, rate):
        require_builds([board])
        fw = None if rate == DEFAULT_BAUD else build_gateway(board, rate)
        sim = cl.simulated_board(board, rate, firmware=fw)
        opened.append(sim)
        gw = Gateway(sim.port, baudrate=rate, timeout=10)
        opened.append(gw)
        loop = cl.ControlLoop(Board(gw))
        loop.setup()
        sim.control.wait(F_CPU // 100)          # the IMU samples at 1 kHz
        return sim, loop

    yield start
    for thing in reversed(opened):
        thing.close() if isinstance(thing, Gateway) else thing.stop()


@pytest.mark.parametrize("board, rate", cases(CORRECT))
def test_the_loop_reads_and_writes_right(loop_on, board, rate):
    sim, loop = loop_on(board, rate)
    seen = []
    cl.run(loop, STEPS, True, lambda k, inputs: seen.append(k) or cl.check_sim_inputs(k, inputs))
    assert seen == list(range(STEPS))
    cl.run(loop, STEPS_ONE, False, cl.check_sim_inputs)
    widths, duties = cl.law(loop, STEPS_ONE - 1, loop.latest)
    # the last step's outputs, read back: the law of the inputs before it
    b = loop.board
    got = b.servo.widths(0, cl.SERVOS)
    assert len(loop.free) == (6 if board == "m32d" else 16)
    assert {ch: got[ch] for ch in loop.free} == {ch: widths[ch] for ch in loop.free}
    assert all(got[ch] == 0 for ch in range(cl.SERVOS) if ch not in loop.free)
    if board == "m32d":
        assert tuple(b.motor.duties()) == duties
    line = sim.control.line()
    assert line["dor"] == line["fe"] == 0


def test_300_steps_at_460800_on_the_m128s(loop_on):
    """Before firmware/uart.c put a byte in its ring and turned UDRIE on
    atomically, the M128-S sent stale bytes now and then at 460800 (a UDRE
    interrupt in between emptied the ring and turned UDRIE off): 300 steps
    always met one."""
    _, loop = loop_on("m128s", 460800)
    cl.run(loop, 300, True, cl.check_sim_inputs)


@pytest.mark.parametrize("board, rate", cases({}))
def test_the_pipelined_loop_keeps_the_wire_busy(loop_on, board, rate):
    """The best of up to TRIES runs (a PC busy with other programs may pause
    the host for longer than the flow window's characters last)."""
    sim, loop = loop_on(board, rate)
    steps = STEPS - WARMUP
    tries = []
    while len(tries) < TRIES and (not tries or tries[-1][0] < TARGET):
        cycles, cpu = cl.timed(loop, STEPS, True, sim.control.time, cl.check_sim_inputs, WARMUP)
        sent, received = loop.last.wire()
        wire = steps * max(sent, received) * 10 * F_CPU / rate
        tries.append((100.0 * wire / cycles, cpu / steps, cycles))
    share, cpu, cycles = max(tries)
    floor = FLOOR.get((board, rate))
    if floor is not None:
        assert share >= floor, "%.1f %% of the wire at best, under this row's floor %.1f %% " \
            "(tries %s)" % (share, floor, ", ".join("%.1f %%" % t[0] for t in tries))
        assert cpu < max(sent, received) * 10 / rate
        if share < TARGET:
            pytest.xfail("issue 20: %.1f %% of the wire: %s" % (share, CPU_BOUND))
    assert share >= TARGET, "%.1f %% of the wire at best (%d steps of %d/%d characters in " \
        "%d cycles; tries %s)" % (share, steps, sent, received, cycles,
                                 ", ".join("%.1f %%" % t[0] for t in tries))
    # the PC is far from the limit: its CPU time a step is under the step's wire time
    assert cpu < max(sent, received) * 10 / rate


@pytest.mark.parametrize("args", [["--board", "m128s"], ["--one-at-a-time"]])
def test_the_example_as_a_program(args):
    """`python3 examples/control_loop.py --sim ...` as a user runs it."""
    import subprocess
    require_builds(["m32d", "m128s"])
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "control_loop.py"), "--sim",
                        "--steps", "10"] + args, capture_output=True, text=True, timeout=120)
    assert (r.returncode, r.stderr) == (0, "")
    first, last = r.stdout.splitlines()
    assert first.startswith("10 steps in ") and " steps/s, Python " in first
    assert last == ("last inputs: ADC [204, 306, 409, 511, 613, 716, 818, 920]; accel 1.00 "
                    "-2.00 9.81 m/s^2, 25.0 C, gyro 10.0 -20.0 30.0 deg/s")


def test_the_example_refuses_a_rate_without_a_build():
    import subprocess
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "control_loop.py"), "--sim",
                        "--baud", "12345"], capture_output=True, text=True, timeout=120)
    assert (r.returncode, r.stdout) == (1, "")
    assert r.stderr.startswith("control_loop: no m32d gateway at 12345 baud: ")
    assert len(r.stderr.splitlines()) == 1


@pytest.mark.parametrize("rate", ["0", "-1", "abc", "1e5", ""])
def test_the_example_refuses_a_baud_that_is_no_rate(rate):
    """--baud that is no rate at all is a usage error (exit 2, argparse's
    line last) before any board starts: 0 and -1 went on to `make BAUD=-1`
    (exit 1)."""
    import subprocess
    r = subprocess.run([sys.executable, str(ROOT / "examples" / "control_loop.py"), "--sim",
                        "--baud=" + rate], capture_output=True, text=True, timeout=60)
    assert (r.returncode, r.stdout) == (2, "")
    assert r.stderr.splitlines()[-1] == ("control_loop.py: error: argument --baud: %r is not a"
                                         " serial rate: a whole number of baud above 0"
                                         " (460800)" % rate)
