"""The sys driver's host side (docs/registers.md "sys"): RESET's bits as
cause names and back, and the register numbers next to the boards' maps."""

import pytest

from orfa import boards


def test_reset_causes_by_name():
    assert boards.reset_causes(0x00) == frozenset()
    assert boards.reset_causes(0x01) == {"power"}
    assert boards.reset_causes(0x0A) == {"external", "watchdog"}
    assert boards.reset_causes(0xFF) == set(boards.RESET_CAUSES)
    assert boards.reset_cause_bits(["watchdog", "brownout"]) == 0x0C
    assert boards.reset_cause_bits(boards.RESET_CAUSES) == boards.RESET_CAUSES_ALL
    with pytest.raises(ValueError):
        boards.reset_cause_bits(["bored"])


def test_sys_is_last_on_every_board():
    for board, uids in boards.BOARD_UIDS.items():
        assert uids[-1] == boards.SYS_UID, board
    # RESET follows the last register of the driver before it
    assert boards.SYS_REGISTER == {"m32d": 0x14, "m128s": 0x0C}
    assert boards.DRIVER_NAMES[boards.SYS_UID].startswith("system")
