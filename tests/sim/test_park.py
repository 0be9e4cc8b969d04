"""Parked boards (docs/simulator.md, "Parked boards"): a board idling in a
loop is not run, its cycle follows world time through the loop. That must
change nothing: a robot under load (servos pulsing on every board, a motor's
PWM, the bus busy at 400 kHz) gives the same trace and the same VCD, cycle
for cycle, as with every board run every quantum (`--no-park`)."""

import re

import pytest

from conftest import F_CPU, require_builds, require_slave
from orfa import boardmap
from orfa.sim import SimBoard

M128S, M32D = 0x10, 0x12
#: Every request at a fixed cycle (far ahead of boot), the next one a gap
#: after the last one's last byte; the comparison ends at END.
START, GAP = 1 << 22, F_CPU // 200
END = START + F_CPU // 2


def reg(board, driver, name):
    return boardmap.load(board).reg(driver, name)


def requests():
    sp32, sp128 = reg("m32d", "servo", "SP"), reg("m128s", "servo", "SP")
    return ["C 0190",
            "S AA %02X 00 05 DC 01 03 E8 P" % sp32,                 # the gateway's servos
            "S %02X %02X 00 05 DC 02 04 00 P" % (M128S, sp128),    # the M128-S's
            "S %02X %02X 02 06 40 P" % (M32D, sp32),               # the M32-D slave's
            "S %02X %02X 80 60 00 01 P" % (M32D, reg("m32d", "motor", "PWM1")),
            "S AA 00 01 S AB 06 P"]


def run(extra):
    """Trace lines and VCD (its date left out) up to END, of a fresh robot."""
    require_builds(["m32d"])
    slaves = [("m128s", M128S, require_slave("m128s", M128S)),
              ("m32d", M32D, require_slave("m32d", M32D))]
    with SimBoard("m32d", trace=True, control=True, vcd=True, slaves=slaves,
                  extra_args=extra) as sim:
        ctl = sim.control
        assert ctl.time() < START
        at = START
        for line in requests():
            at = ctl.rx(at, (line + "\r").encode()) + GAP
        reads = b"".join(b"S %02X 00 S %02X 08 P        \r" % (a, a | 1) for a in (M128S, M32D))
        while at < END:
            at = ctl.rx(at, reads)
        ctl.wait(at - ctl.time() + F_CPU // 100)
        sim.stop(keep_dir=True)
        trace = [l for l in sim.trace_text().splitlines() if int(l.split()[0]) < END]
        vcd = re.sub(r"\$date.*?\$end", "", sim.vcd_path.read_text(), flags=re.S)
    head, _, body = vcd.partition("$enddefinitions $end")
    lines = body.splitlines()
    end = END * 10 ** 7 // F_CPU        # in the VCD's unit, 100 ns
    assert "$timescale 100ns $end" in " ".join(head.split())
    cut = next((k for k, l in enumerate(lines) if l.startswith("#") and int(l[1:]) >= end),
               len(lines))
    return trace, head, lines[:cut]


@pytest.fixture(scope="module")
def both():
    return run(["--no-park"]), run([])


def test_the_load_reaches_every_board(both):
    trace = both[0][0]
    for addr in (M128S, M32D):
        assert any("twi addr %02X ack" % addr in l for l in trace), trace[-20:]
    assert sum(" uart tx " in l for l in trace) > 500


def test_parked_boards_give_the_same_trace(both):
    assert both[1][0] == both[0][0]


def test_parked_boards_give_the_same_vcd(both):
    assert both[1][1] == both[0][1]
    assert both[1][2] == both[0][2]
