"""The simulated SRF08 range finder (--srf08, docs/simulator.md) as a PC sees
it through the gateway's serial port, with what it senses set over the
control socket and every wait in simulated cycles (control `wait`, or bytes
scheduled on the serial line with `rx`), never on the wall clock.

Numbers from Devantech's SRF08 technical specification: 65 ms of ranging
with the range register at 255, (R + 1) x 43 mm of range (24 -> about 1 m),
results high byte first in locations 2,3 (4,5 the next echo), location 1
the light reading, location 0 the software revision; while ranging the
SRF08 does not answer the bus (the gateway: ERROR 06, address not
acknowledged). The simulator's speed of sound is 343.75 m/s.
"""

import re

import pytest

from orfa.protocol import F_CPU
from orfa.sim import BOARDS
from orfa.simctl import SimControlError

from conftest import ControlBench, bench_running, for_each_test

SRF = 0xE0
MS65 = F_CPU * 65 // 1000            # a ranging at range 255
RANGE24 = MS65 * 25 // 256           # 46800 cycles: at range 24 (0x18)
REVISION = 0x0A                      # sim/parts/srf08.h (the document names none)
#: How far ahead of "now" bytes are scheduled with `rx`: half a simulated
#: second, so the request reaches the simulator in time even on a busy host.
LEAD = F_CPU // 2
#: The document's way to wait: read location 0 (the revision) until it is not 255.
POLL = "S E0 00 S E1 01 P"
POLL_OK = b"SWASR%02XP\r\n" % REVISION


SrfBench = ControlBench


@pytest.fixture(scope="module", params=BOARDS)
def srf_bench(request):
    yield from bench_running(request.param, SrfBench, trace=True, control=True, srf08=(SRF,))


def srf_power_up(b):
    """The SRF08 back at its power-up settings, nothing in front."""
    b.ctl.wait(MS65)                                # any ranging is over
    assert b.ask("S E0 01 1F FF P") == b"SWAAAP\r\n"  # gain 31, range 255
    b.ctl.srf08_range(SRF, 0)
    b.ctl.srf08_light(SRF, 0)


@pytest.fixture
def srf(srf_bench):
    """The board with its SRF08 idle, at power-up settings, nothing in front."""
    yield from for_each_test(srf_bench, tidy=srf_power_up, settle=True)


def echo_reply(*values: int) -> bytes:
    return b"SWASR" + b"".join(b"%04X" % v for v in values) + b"P\r\n"


def test_ranging_in_cm(srf):
    """The document's sequence: 0x51 to location 0, wait 65 ms, read 2,3."""
    srf.ctl.srf08_range(SRF, 1234)
    assert srf.ask("S E0 00 51 P") == b"SWAAP\r\n"
    srf.ctl.wait(MS65)
    assert srf.ask("S E0 02 S E1 02 P") == echo_reply(123)     # 1234 mm -> 123 cm


def test_busy_until_65_ms(srf):
    """Deaf from the command's byte for exactly the ranging time: a poll of
    location 0 is not acknowledged before, answered from then on. The
    requests are put on the serial line at chosen cycles so that the polls
    land just before and just after the end, whatever the wall clock does."""
    ctl = srf.ctl
    # calibrate: cycles from a request's first byte on the line to its bus event
    mark = srf.mark()
    t = ctl.time() + LEAD
    srf.rx(t, "S E0 00 51 P")
    assert srf.read_lines(1) == b"SWAAP\r\n"
    start = srf.twi(mark, "write")[-1]
    assert start[1] == ("51", "ack")
    cmd_lag = start[0] - t
    ctl.wait(MS65)
    mark = srf.mark()
    t = ctl.time() + LEAD
    srf.rx(t, POLL)
    assert srf.read_lines(1) == POLL_OK
    poll_lag = srf.twi(mark, "addr")[-2][0] - t      # the E0 of the poll

    # the measurement: a command, then polls early, just before and just after
    mark = srf.mark()
    t = ctl.time() + LEAD
    srf.rx(t, "S E0 00 51 P")
    done = t + cmd_lag + MS65                       # expected end of ranging
    for bus_cycle in (t + 40000, done - 10000, done + 10000):
        srf.rx(bus_cycle - poll_lag, POLL)
    replies = srf.read_lines(4)
    start = [c for c, f in srf.twi(mark, "write") if f == ("51", "ack")]
    assert len(start) == 1
    addrs = [(c, f[1]) for c, f in srf.twi(mark, "addr") if f[0] == "E0" and c > start[0]]
    assert len(addrs) == 3, addrs
    for cycle, ack in addrs:
        assert (ack == "ack") == (cycle >= start[0] + MS65), (cycle, start[0], addrs)
    assert [ack for _, ack in addrs] == ["nack", "nack", "ack"]
    assert replies == b"SWAAP\r\n" + b"ERROR 06\r\n" * 2 + POLL_OK


def test_light_sensor(srf):
    """Location 1: the light level, read when the ranging starts."""
    srf.ctl.srf08_light(SRF, 77)
    assert srf.ask("S E0 00 51 P") == b"SWAAP\r\n"
    srf.ctl.srf08_light(SRF, 200)           # brighter after the ping
    srf.ctl.wait(MS65)
    assert srf.ask("S E0 01 S E1 01 P") == b"SWASR4DP\r\n"     # 77
    assert srf.ask("S E0 00 50 P") == b"SWAAP\r\n"
    srf.ctl.wait(MS65)
    assert srf.ask("S E0 01 S E1 01 P") == b"SWASRC8P\r\n"     # 200


def test_inches_and_microseconds(srf):
    srf.ctl.srf08_range(SRF, 1234)
    assert srf.ask("S E0 00 50 P") == b"SWAAP\r\n"
    srf.ctl.wait(MS65)
    assert srf.ask("S E0 02 S E1 02 P") == echo_reply(49)      # 48.6 in
    assert srf.ask("S E0 00 52 P") == b"SWAAP\r\n"
    srf.ctl.wait(MS65)
    assert srf.ask("S E0 02 S E1 02 P") == echo_reply(7180)    # 2 x 1234 mm / 0.34375
    # the read continues at location 4: no second echo
    assert srf.ask("S E1 02 P") == b"SR0000P\r\n"


def test_two_echoes_nearest_first(srf):
    srf.ctl.srf08_range(SRF, 2000, 800)
    assert srf.ask("S E0 00 51 P") == b"SWAAP\r\n"
    srf.ctl.wait(MS65)
    assert srf.ask("S E0 02 S E1 06 P") == echo_reply(80, 200, 0)


def test_range_register(srf):
    """24 (0x18): about 1 m (1075 mm) and a ranging of 46800 cycles: the
    bus is answered well before 65 ms; farther targets read 0."""
    ctl = srf.ctl
    assert srf.ask("S E0 02 18 P") == b"SWAAP\r\n"
    assert ctl.srf08(SRF)["rangereg"] == 24
    ctl.srf08_range(SRF, 1234)
    mark = srf.mark()
    end = srf.rx(ctl.time() + LEAD, "S E0 00 51 P")
    srf.rx(end + RANGE24 + 20000, "S E0 02 S E1 02 P")
    assert srf.read_lines(2) == b"SWAAP\r\n" + echo_reply(0)
    start = [c for c, f in srf.twi(mark, "write") if f == ("51", "ack")][0]
    answered = [c for c, f in srf.twi(mark, "addr") if f == ("E0", "ack")][-1]
    assert start + RANGE24 <= answered < start + MS65
    ctl.srf08_range(SRF, 1000)
    assert srf.ask("S E0 00 51 P") == b"SWAAP\r\n"
    ctl.wait(RANGE24)
    assert srf.ask("S E0 02 S E1 02 P") == echo_reply(100)


def test_gain_register_accepted(srf):
    assert srf.ask("S E0 01 10 P") == b"SWAAP\r\n"
    assert srf.ctl.srf08(SRF)["gain"] == 0x10


def test_address_change(srf):
    """A0, AA, A5, new address: four separate writes to location 0."""
    try:
        for byte in ("A0", "AA", "A5", "F2"):
            assert srf.ask("S E0 00 %s P" % byte) == b"SWAAP\r\n"
        assert srf.ask("S E1 01 P") == b"ERROR 06\r\n"
        assert srf.ask("S F2 00 S F3 01 P") == b"SWASR%02XP\r\n" % REVISION
        assert srf.ctl.srf08(0xF2)["addr"] == 0xF2
    finally:
        for byte in ("A0", "AA", "A5", "E0"):
            srf.ask("S F2 00 %s P" % byte)
    assert srf.ask("S E0 00 S E1 01 P") == b"SWASR%02XP\r\n" % REVISION


def test_control_errors(srf):
    ctl = srf.ctl
    for bad in ("srf08", "srf08 E2 range 5", "srf08 E0 range -1", "srf08 E0 range x",
                "srf08 E0 range 100001", "srf08 E0 light 256", "srf08 E0 bogus 1",
                "srf08 E0 range 1 2 3"):
        with pytest.raises(SimControlError, match="^ERR "):
            ctl.request(bad)
    assert ctl.request("srf08 E0 range 500 900") == "OK"
    assert ctl.srf08(SRF)["range"] == (500, 900)
    assert ctl.request("srf08 0xE0 light 5") == "OK"
    assert ctl.srf08(SRF)["light"] == 5


def test_sense_sets_what_the_srf08_sees(srf):
    """The generic `sense @ADDR QUANTITY V...` reaches the same state as the
    `srf08` request, and the ranger measures it."""
    ctl = srf.ctl
    assert ctl.request("sense @E0 range 1234") == "OK"
    assert ctl.request("sense @0xE0 light 77") == "OK"
    assert ctl.srf08(SRF)["range"] == (1234, 0) and ctl.srf08(SRF)["light"] == 77
    assert srf.ask("S E0 00 51 P") == b"SWAAP\r\n"
    ctl.wait(MS65)
    assert srf.ask("S E0 01 S E1 03 P") == b"SWASR4D007BP\r\n"   # light 77, 123 cm
    assert ctl.request("sense @E0 range 500 900") == "OK"
    assert ctl.srf08(SRF)["range"] == (500, 900)


@pytest.mark.parametrize("bad, says", [
    ("sense @E0 accel 0 0 9.8", "an SRF08 senses range"),
    ("sense @E0 range -1", "0..100000 mm"),
    ("sense @E0 range 1 2 3", "an SRF08 senses range"),
    ("sense @E0 light 256", "0..255"),
    ("sense @E0 range x", "'x' is not a number"),
    ("sense @E0 range nan", "'nan' is not a number"),
    ("sense @E0 bogus 1", "no quantity 'bogus'"),
    ("sense @E4 range 5", "no part at E4"),
    ("sense @ZZ range 5", "ADDR the part's 8-bit bus address"),
    ("sense @E0", "unknown request or wrong arguments"),
])
def test_sense_errors(srf, bad, says):
    with pytest.raises(SimControlError, match="^ERR .*" + re.escape(says)):
        srf.ctl.request(bad)
    assert srf.ctl.srf08(SRF)["range"] == (0, 0)      # nothing changed


def test_sense_from_python(srf):
    srf.ctl.sense(SRF, "range", 2000, 800)
    assert srf.ctl.srf08(SRF)["range"] == (2000, 800)
    with pytest.raises(SimControlError, match="0..255"):
        srf.ctl.sense(SRF, "light", 300)
