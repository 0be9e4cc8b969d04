"""The simulated CPU takes a pending interrupt as the AVR does: after one
more instruction following SEI, and one following RETI (the ATmega32
datasheet, "Reset and Interrupt Handling"). simavr 1.6 runs two; the
harness corrects it (sim/simavr16/interrupt.h, docs/simulator.md, "What
simavr 1.6 gets wrong"). The firmware is tests/sim/fw/irq_latency.c."""
import pytest

from orfa.sim import REPO_ROOT, SimBoard

ELF = REPO_ROOT / "build" / "sim-fw" / "irq_latency.elf"
PORTA = 0x3B        # its data address on the ATmega32


def test_one_instruction_after_sei_and_after_reti():
    if not ELF.is_file():
        pytest.fail("missing %s: run `make sim`" % ELF, pytrace=False)
    with SimBoard("m32d", control=True, firmware=ELF) as sim:
        ctl = sim.control
        ctl.wait(20000)
        after_sei, after_reti = ctl.peek(PORTA)[0] & 0x0F, ctl.peek(PORTA)[0] >> 4
    assert (after_sei, after_reti) == (1, 2), \
        "INCs run before the first interrupt %d (want 1), before the second %d (want 2)" \
        % (after_sei, after_reti)
