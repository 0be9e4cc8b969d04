"""The control request `wait i2c N WITHIN` (docs/simulator.md, "Control
interface"): it answers once the bus's master has clocked N more bytes, at
most a quantum and an instruction after the trace's `twi addr|write|read`
of the N-th; an error line when WITHIN cycles pass first; a one-line error
for bad numbers. On a gateway alone (one board: its run to the cycle) and
with a slave board (the boards in lock-step)."""

import pytest

from conftest import require_builds, require_slave, running
from orfa.errors import SimControlError
from orfa.sim import BOARDS, SimBoard

#: The answer's cycle after the byte's: the quantum the boards run in while
#: a client waits for bytes (WORLD_QUANTUM, sim/harness/world.h) and the
#: instruction (or interrupt entry) the gateway was in at its end.
SLACK = 4 + 5
#: Cycles: the request is on the bus by then, after the gateway's quiet time
#: after its reset or a fault (36 ms, docs/protocol.md "Abandoned frames").
WITHIN = 400000
QUIET = 270000
BYTES = ("twi addr", "twi write", "twi read")


@pytest.fixture(scope="module", params=[(b, s) for b in BOARDS for s in (False, True)],
                ids=["%s%s" % (b, "+slave" if s else "") for b in BOARDS for s in (False, True)])
def bench(request):
    board, with_slave = request.param
    require_builds([board])
    slaves = [("m32d", 0x12, require_slave("m32d", 0x12))] if with_slave else []
    with running(SimBoard(board, eeproms=(0xA0,), control=True, trace=True,
                          slaves=slaves)) as b:
        yield b


def test_answers_at_the_bytes(bench):
    """An EEPROM read of two bytes after a register write: address, register,
    address, two reads. Waits for 1, then 2 more, then 2 more bytes answer
    at the 1st, 3rd and 5th byte's end (a read counts as a written one)."""
    b = bench
    ctl = b.sim.control
    req = b"S A0 00 S A1 02 P\r"
    began = ctl.time()
    out = ctl.requests(["rx +1000 %s" % req.hex(), "wait i2c 1 %d" % WITHIN,
                        "wait i2c 2 %d" % WITHIN, "wait i2c 2 %d" % WITHIN])
    assert b.read_lines(1).startswith(b"SWASR")
    ev = [e for e in b.sim.trace_events(kinds=BYTES) if e.cycle >= began]
    assert [e.kind for e in ev] == ["twi addr", "twi write", "twi addr", "twi read", "twi read"]
    for answer, byte in zip(out[1:], (ev[0], ev[2], ev[4])):
        assert 0 <= int(answer) - byte.cycle <= SLACK, (answer, byte)


def test_the_bound_gives_its_error(bench):
    """No byte within WITHIN: the error at now + WITHIN, with what came (here
    the 3 bytes of a write, of 10 waited for); the requests behind it go on
    from that cycle."""
    ctl = bench.sim.control
    now = ctl.time()
    with pytest.raises(SimControlError) as err:
        ctl.wait_i2c(1, 5000)
    words = str(err.value).split()
    assert words[:6] == ["ERR", "wait", "i2c:", "0", "of", "1"], err.value
    bound = int(words[-1])
    assert now + 5000 <= bound <= ctl.time()
    req = b"S A0 10 5A P\r"
    with pytest.raises(SimControlError, match=r"^ERR wait i2c: 3 of 10 bytes by cycle \d+$"):
        ctl.requests(["rx +1000 %s" % req.hex(), "wait i2c 10 %d" % WITHIN])
    assert bench.read_lines(1) == b"SWAAP\r\n"


@pytest.mark.parametrize("line", ["wait i2c", "wait i2c 3", "wait i2c 0 100", "wait i2c 1 0",
                                  "wait i2c x 100", "wait i2c 1 -5", "wait i2c 1000001 100",
                                  "wait i2c 1 1099511627777", "wait i2c 1 100 7"])
def test_bad_numbers_give_one_error_line(bench, line):
    """A one-line error naming the form, then the next request's own reply
    (nothing waits)."""
    ctl = bench.sim.control
    with pytest.raises(SimControlError) as err:
        ctl.requests([line, "time"])
    text = str(err.value)
    assert text.startswith(("ERR wait i2c N WITHIN: N bytes 1..1000000",
                            "ERR unknown request or wrong arguments")), text
    assert "\n" not in text
    assert ctl.time() > 0


def test_help_lists_it(bench):
    assert "wait N | wait i2c N WITHIN |" in bench.sim.control.request("help")


def test_requests_behind_act_at_the_byte(bench):
    """SCL held by a device right after a write's second byte: the third
    byte, begun, never ends (the master times out), and the trace has the
    hold after the second byte's end, within the slack. (Last: the gateway
    keeps the bus quiet for a while after giving up.)"""
    b = bench
    ctl = b.sim.control
    req = b"S A0 10 5A 5B P\r"
    began = ctl.time()
    try:
        out = ctl.requests(["rx +1000 %s" % req.hex(), "wait i2c 2 %d" % WITHIN,
                            "i2c hold-scl on", "wait 100000", "i2c hold-scl off", "wait %d" % QUIET])
        assert b.read_lines(1).startswith(b"ERROR")
    finally:
        ctl.i2c_hold_scl(False)
    ev = [e for e in b.sim.trace_events(kinds=BYTES + ("twi hold-scl",)) if e.cycle >= began]
    kinds = [e.kind for e in ev]
    assert kinds[:3] == ["twi addr", "twi write", "twi hold-scl"], kinds
    assert "twi write" not in kinds[3:], kinds
    assert 0 <= ev[2].cycle - ev[1].cycle <= SLACK
    assert ev[2].cycle == int(out[1])


@pytest.mark.parametrize("with_slave", [False, True], ids=["alone", "slave"])
def test_parked_boards_give_the_same_cycles(with_slave):
    """While a client waits for bytes the boards idling stay parked (the run
    stops at the quantum of the byte itself): that changes no answer, the
    same cycles as with every board run every quantum (`--no-park`), for a
    request at a fixed cycle."""
    require_builds(["m32d"])
    slaves = [("m32d", 0x12, require_slave("m32d", 0x12))] if with_slave else []
    req = b"S A0 00 S A1 02 P\r"
    at, within = 1 << 22, 1 << 23

    def answers(extra):
        with SimBoard("m32d", eeproms=(0xA0,), control=True, slaves=slaves,
                      extra_args=extra) as sim:
            return sim.control.requests(["rx %d %s" % (at, req.hex())] +
                                        ["wait i2c %d %d" % (n, within) for n in (1, 2, 2)])

    parked = answers([])
    assert parked == answers(["--no-park"])
    assert int(parked[1]) > at
