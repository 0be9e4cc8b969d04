"""A robot builder's own tests, written against the orfa pytest plugin.

Not collected here (the name is not test_*): tests/sim/test_pytest_plugin.py
and tests/host/test_install.py copy it into a temporary directory as
test_robot_code.py and run pytest on it there, as a user would.
"""

import pytest
import serial

from orfa import boardmap

F_CPU = boardmap.load("m32d").f_cpu


def test_default_board_on_the_wire(orfa_sim_board):
    assert orfa_sim_board.board == "m32d"
    assert " atmega32 @ " in orfa_sim_board.banner
    with serial.serial_for_url(orfa_sim_board.port, baudrate=115200, timeout=5) as port:
        port.write(b"V\n")
        assert port.read_until(b"\r\n") == b"V1.1\r\n"


def test_simulated_time(orfa_sim_board):
    start = orfa_sim_board.control.time()
    reached = orfa_sim_board.wait_s(0.25)
    assert reached >= start + F_CPU // 4
    assert orfa_sim_board.control.time() >= reached    # it runs on after the wait


@pytest.mark.orfa_board("m128s", eeproms=[0xA0])
def test_marker_sets_board_and_options(orfa_sim_board):
    assert " atmega128 @ " in orfa_sim_board.banner
    with orfa_sim_board.gateway(timeout=5) as gw:
        assert gw.request("S A0 P") == "SWP"          # the marker's EEPROM
        assert gw.request("S A2 P") == "ERROR 06"     # nothing there


@pytest.mark.parametrize("orfa_sim_board", ["m32d", "m128s"], indirect=True)
def test_indirect_board(orfa_sim_board):
    mcu = boardmap.load(orfa_sim_board.board).mcu
    assert " %s @ " % mcu in orfa_sim_board.banner
    with orfa_sim_board.gateway(timeout=5) as gw:
        assert gw.request("S A0 P") == "ERROR 06"     # no EEPROM unless asked


def test_default_robot(orfa_sim_robot):
    with orfa_sim_robot.gateway(timeout=5) as gw:
        own = [d.uid for d in gw.drivers()]
        # the M32-D slave at 0x12 has the drivers of the M32-D gateway
        assert [d.uid for d in gw.drivers(0x12)] == own
        assert [d.uid for d in gw.drivers(0x10)] == [
            d.uid for d in boardmap.load("m128s").drivers]
        assert gw.request("S 14 P") == "ERROR 06"     # no third slave
    # the control socket reaches the slave's own pins: an input after reset
    assert orfa_sim_robot.control.slave(0x10).pin("F0")[1] == "in"


@pytest.mark.orfa_robot(gateway="m128s", slaves=[("m32d", 0x16)])
def test_marker_robot(orfa_sim_robot):
    assert " atmega128 @ " in orfa_sim_robot.banner
    with orfa_sim_robot.gateway(timeout=5) as gw:
        assert gw.request("S 16 P") == "SWP"
        assert gw.request("S 10 P") == "ERROR 06"
        uids = [d.uid for d in boardmap.load("m32d").drivers]
        assert [d.uid for d in gw.drivers(0x16)] == uids


def test_typed_board_moves_a_servo(orfa_board, orfa_sim_board):
    """The typed API on the simulated board: the width lands on the pin."""
    orfa_board.servo.set_width(3, 1500)
    assert orfa_board.servo.width(3) == 1500
    ctl = orfa_sim_board.control
    ctl.wait(3 * 147456)                                # three 20 ms frames
    lo, hi, _ = ctl.measure("A3", 2, ctl.time() - 2 * 147456)["high"]   # servo 3: PA3
    assert abs(lo - 1500 * F_CPU / 1e6) <= 4 and abs(hi - 1500 * F_CPU / 1e6) <= 4, (lo, hi)


@pytest.mark.orfa_robot(gateway="m32d", slaves=[("m128s", 0x10)])
def test_typed_boards_of_a_robot(orfa_robot_boards):
    assert sorted(orfa_robot_boards) == [0x10, 0xAA]
    slave = orfa_robot_boards[0x10]
    assert slave.map.board == "m128s"
    slave.servo.set_width(5, 2000)
    assert slave.servo.widths(5, 1) == [2000]
