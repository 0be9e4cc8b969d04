"""A gateway opened on a board that holds a partial line (someone typed
`S AA 0` in a terminal and closed it; a program at another rate) ends it
first, so the first request is answered as itself: Python's Gateway, the
`orfa` command and the console. Scripted lines: tests/host/test_line_contents.py."""

import pytest
import serial

from orfa import cli
from orfa.sim import BOARDS, SimBoard

from conftest import REPLY_TIMEOUT, board_sent, require_builds

NAMES = {"m32d": "m32d (OR-AVR-M32-D)", "m128s": "m128s (OR-AVR-M128-S)"}


def leave(sim: SimBoard, left: str) -> None:
    """What a program before this one left in the board."""
    if left == "9600":
        # a program at 9600 wrote a request without its line end
        with serial.Serial(sim.port, 9600, timeout=0) as port:
            sim.pc_write(port, b"S AA 00 00 S AB 01 P")
            sim.wait_s(25 * 10 / 9600)
    elif left == "terminal write":
        # a whole request typed, its Enter never: ending it must not run it
        sim.control.rx_after(100, b"S AA 15 00 00 P")   # run, it would answer SWAAAP
        sim.wait_s(0.002)
    else:
        sim.control.rx_after(100, left.encode("ascii"))
        sim.wait_s(0.002)


LEFT = ["S AA 0", "V", "  s aa 1", "9600", "terminal write"]


@pytest.mark.parametrize("left", LEFT)
@pytest.mark.parametrize("board", BOARDS)
def test_the_first_request_of_a_gateway_is_answered_as_itself(board, left):
    require_builds([board])
    with SimBoard(board, control=True, trace=True) as sim:
        leave(sim, left)
        t0 = sim.control.time()
        with sim.gateway(timeout=REPLY_TIMEOUT) as gw:
            assert gw.request("V") == "V1.1"
            assert gw.request("L") == "LAA"
            assert gw.request("V") == "V1.1"
        if left == "terminal write":
            sent = board_sent(sim, t0)
            assert b"SWAAAP" not in sent, sent


@pytest.mark.parametrize("left", ["S AA 0", "9600"])
def test_orfa_version_after_a_partial_line(left, capsys):
    require_builds(["m32d"])
    with SimBoard("m32d", control=True, trace=True) as sim:
        leave(sim, left)
        status = cli.main(["--port", sim.port, "--timeout", str(REPLY_TIMEOUT), "version"])
        out, err = capsys.readouterr()
        assert (status, out, err) == (0, "protocol 1.1\nboard    %s\n" % NAMES["m32d"], "")


def test_the_console_after_a_partial_line(capsys, monkeypatch):
    require_builds(["m32d"])
    import io
    with SimBoard("m32d", control=True, trace=True) as sim:
        leave(sim, "S AA 0")
        monkeypatch.setattr("sys.stdin", io.StringIO("V\nL\n"))
        status = cli.main(["--port", sim.port, "--timeout", str(REPLY_TIMEOUT), "console"])
        out, err = capsys.readouterr()
        assert (status, out, err) == (0, "V1.1\nLAA\n", "")


def test_a_clean_line_costs_one_round_trip():
    """On a clean line the sync is a refused `!`, a V and a C: three reply
    lines, then the first request's."""
    require_builds(["m32d"])
    with SimBoard("m32d", control=True, trace=True) as sim:
        t0 = sim.control.time()
        with sim.gateway(timeout=REPLY_TIMEOUT) as gw:
            assert gw.request("V") == "V1.1"
        assert board_sent(sim, t0) == b"ERROR 02\r\nV1.1\r\nC0063\r\nV1.1\r\n"
