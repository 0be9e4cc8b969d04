"""The simulator's `profile` request (sim/harness/profile.c): every cycle a
board runs while profiled counts once, to the instruction it belongs to.
The firmware is tests/sim/fw/profile_loop.c: NOP, NOP, RJMP back, 4 cycles a
turn (a loop the simulator would otherwise park, skipping its instructions);
and tools/profile.py, which makes a table of the counts."""
import re
import subprocess
import sys

import pytest

from orfa.sim import REPO_ROOT, SimBoard
from orfa.simctl import SimControlError

ELF = REPO_ROOT / "build" / "sim-fw" / "profile_loop.elf"


SLEEP_ELF = REPO_ROOT / "build" / "sim-fw" / "profile_sleep.elf"


def loop_address(elf=ELF, label="profile_loop"):
    if not elf.is_file():
        pytest.fail("missing %s: run `make sim`" % elf, pytrace=False)
    out = subprocess.run(["avr-nm", str(elf)], capture_output=True, text=True, check=True).stdout
    return next(int(f[0], 16) for f in (line.split() for line in out.splitlines())
                if f[-1] == label)


def profiled(elf, cycles):
    """(cycle at `profile on`, cycle at the read, the counts) of `cycles`
    cycles of `elf` on an M32-D, profiled in one batch."""
    with SimBoard("m32d", control=True, firmware=elf) as sim:
        ctl = sim.control
        ctl.wait(1000)
        replies = ctl.requests(["profile on", "time", "wait %d" % cycles, "time", "profile"])
    return int(replies[1]), int(replies[3]), {int(a, 16): int(c) for a, _, c in
                                              (x.partition(":") for x in replies[4].split()[1:])}


def test_each_cycle_counts_once_to_its_instruction():
    at = loop_address()
    t0, t1, counts = profiled(ELF, 40000)
    assert sum(counts.values()) == t1 - t0 >= 40000
    assert set(counts) == {at, at + 2, at + 4}
    nop1, nop2, rjmp = counts[at], counts[at + 2], counts[at + 4]
    # turns of 1 + 1 + 2 cycles, the profile begun and read anywhere in a turn
    assert abs(nop1 - nop2) <= 1 and abs(rjmp - 2 * nop1) <= 2


def test_a_sleep_counts_to_its_sleep_instruction():
    """tests/sim/fw/profile_sleep.c: SLEEP, NOP, RJMP, woken every 262144
    cycles while other timers fire in each sleep; the sleep's cycles are the
    SLEEP's (they went to the NOP after it, not yet run, from the first
    timer in a sleep on)."""
    at = loop_address(SLEEP_ELF, "profile_sleep")
    t0, t1, counts = profiled(SLEEP_ELF, 2000000)
    assert sum(counts.values()) == t1 - t0
    wakes = (t1 - t0) // 262144
    assert counts[at] > t1 - t0 - 1000
    assert counts[at + 2] <= wakes + 1 and counts[at + 4] <= 2 * (wakes + 1)


def total(reply):
    return sum(int(x.partition(":")[2]) for x in reply.split()[1:])


def test_off_keeps_the_counts_and_on_starts_again():
    """(The simulation runs on between requests: what is timed goes in one
    batch, the requests answered in order at the cycles they come to.)"""
    with SimBoard("m32d", control=True, firmware=ELF) as sim:
        ctl = sim.control
        r = ctl.requests(["profile on", "time", "wait 5000", "time", "profile off", "profile"])
        assert total(r[5]) == int(r[3]) - int(r[1]) >= 5000
        ctl.wait(5000)
        assert ctl.request("profile") == r[5]       # not counting while off
        r = ctl.requests(["profile on", "time", "wait 1000", "time", "profile"])
        assert total(r[4]) == int(r[3]) - int(r[1]) >= 1000   # from zero again
        assert total(ctl.requests(["wait 100", "profile"])[1]) >= total(r[4]) + 100  # still on


def test_wrong_uses_are_one_line_errors():
    with SimBoard("m32d", control=True, firmware=ELF) as sim:
        ctl = sim.control
        with pytest.raises(SimControlError, match="profile: not on"):
            ctl.profile()
        with pytest.raises(SimControlError, match="profile"):
            ctl.request("profile sideways")


def run_tool(*args):
    return subprocess.run([sys.executable, str(REPO_ROOT / "tools" / "profile.py")] + list(args),
                          capture_output=True, text=True, timeout=300)


def test_the_profile_tool_adds_up():
    """tools/profile.py on the M32-D at 230400: its rows (the rest in one)
    add up to the work a step it states, the idle row apart."""
    r = run_tool("--steps", "4", "--top", "6")
    assert (r.returncode, r.stderr) == (0, "")
    out = r.stdout.splitlines()
    assert out[0].startswith("M32-D gateway at 230400 baud: 4 steps of the pipelined control "
                             "loop (142 characters in, 140 out a step)")
    assert out[1].split() == ["file", "cycles", "work"]
    rows = out[2:-2]
    assert len(rows) == 7 and rows[-1].startswith("(") and " more)" in rows[-1]
    assert rows[0].split()[0] in ("firmware/uart.c", "serialgate/sg_parse.c")
    assert out[-2].startswith("idle (lines marked `profile: idle`)")
    last = re.match(r"work a step (\d+) cycles, the step's wire 45440: the board's time allows "
                    r"([\d.]+) % of the wire; the loop made ([\d.]+) %$", out[-1])
    assert last, out[-1]
    work = int(last.group(1))
    assert abs(sum(int(row.split()[-2]) for row in rows) - work) <= len(rows)
    assert 30000 < work < 90000
    shares = [float(row.split()[-1].rstrip("%")) for row in rows]
    assert abs(sum(shares) - 100.0) < 0.1 * len(rows)


@pytest.mark.parametrize("args", [["--steps", "0"], ["--baud", "9600"], ["--by", "colour"],
                                  ["--top", "x"]])
def test_the_profile_tool_refuses_wrong_arguments(args):
    r = run_tool(*args)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.splitlines()[-1].startswith("profile: error: ")


CHARACTER_WORK = ("firmware/uart.c", "serialgate/sg_rx.c", "serialgate/sg_parse", "serialgate/sg_gate.c",
                  "(the vector table)")


@pytest.mark.parametrize("board, wire", [("m32d", 22720), ("m128s", 20800)])
def test_at_460800_the_characters_alone_fill_the_wire(board, wire):
    """docs/python.md's claim, measured: at 460800 a control-loop step's
    characters (the serial interrupts, parsing, queueing the replies) take
    about the step's whole wire time, so the board's work a step is far
    beyond what 95 % of the wire allows."""
    r = run_tool("--board", board, "--baud", "460800", "--steps", "10", "--top", "100")
    assert (r.returncode, r.stderr) == (0, "")
    out = r.stdout.splitlines()
    rows = [re.match(r"(.*?)\s+(\d+)\s+[\d.]+%$", line) for line in out[2:-2]]
    chars = sum(int(m.group(2)) for m in rows if m.group(1).startswith(CHARACTER_WORK))
    work = int(re.match(r"work a step (\d+) cycles, the step's wire %d:" % wire, out[-1]).group(1))
    assert chars >= 0.9 * wire
    assert work > 1.5 * wire


def test_the_profile_tool_says_a_failed_binutils_run_in_one_line(monkeypatch, capsys):
    """avr-nm or avr-addr2line exiting non-zero: exit 1, one line."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("profile_tool", REPO_ROOT / "tools" / "profile.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)

    def fails(*_):
        raise subprocess.CalledProcessError(1, ["avr-nm", "orfa.elf"])
    monkeypatch.setattr(tool, "build", lambda board, baud: "orfa.elf")
    monkeypatch.setattr(tool, "profile_steps", lambda *_: ({0: 1}, 1, 1, 1))
    monkeypatch.setattr(tool, "classify", fails)
    assert tool.main([]) == 1
    err = capsys.readouterr().err
    assert err.startswith("profile: Command ") and err.count("\n") == 1
