"""The simulator's `flag` control request (sim/harness/isr_watch.c,
docs/simulator.md): how long an interrupt's flag stays raised before its
handler takes it or the firmware clears it."""

import pytest

from conftest import require_builds
from orfa.sim import SimBoard
from orfa.simctl import SimControlError

#: The ATmega32's Timer2 overflow vector: the M32-D's clock tick, a wrap
#: of 2048 cycles.
TIMER2_OVF = 5


def test_an_idle_boards_clock_tick_is_taken_at_once():
    require_builds(["m32d"])
    with SimBoard("m32d", control=True) as sim:
        ctl = sim.control
        # the watch starts; the simulator runs free: the wraps counted are
        # those between the two answers' cycles
        start = int(ctl.requests(["flag %d" % TIMER2_OVF, "time"])[1])
        ctl.wait(100 * 2048)
        reply, end, after = ctl.requests(["flag %d clear" % TIMER2_OVF, "time",
                                          "flag %d" % TIMER2_OVF])
        count, longest = int(reply.split()[3]), int(reply.split()[1])
        assert abs(count - (int(end) - start) / 2048) <= 1, (count, start, end)
        assert count >= 99 and longest < 100, reply
        assert after.split()[3] == "0", after     # cleared
        with pytest.raises(SimControlError, match="no vector 99"):
            ctl.flag(99)
