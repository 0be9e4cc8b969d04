"""pytest fixtures for testing robot code against simulated boards.

Loaded by the `pytest11` entry point wherever orfa is installed (or with
`pytest -p orfa.pytest_plugin`). Each fixture starts its own simulator for
the test and stops it after; the control socket is on (`.control`,
`.wait_s()`), the trace off unless asked for.

    def test_lamp(orfa_sim_board):                   # an M32-D gateway
        with orfa_sim_board.gateway() as gw:
            assert gw.request("V") == "V1.1"

    @pytest.mark.orfa_board("m128s", eeproms=[0xA0]) # any SimBoard option
    def test_eeprom(orfa_sim_board): ...

    @pytest.mark.parametrize("orfa_sim_board", ["m32d", "m128s"], indirect=True)
    def test_both(orfa_sim_board): ...

    @pytest.mark.orfa_robot(gateway="m32d", slaves=[("m128s", 0x10)])
    def test_arm(orfa_sim_robot): ...

The board is, first that applies: the indirect parameter, the marker's
board, `--orfa-board` on the command line (default m32d). A robot without a
marker is the demo robot: an M128-S slave at 0x10 and an M32-D at 0x12.
"""

from __future__ import annotations

import inspect
from typing import Any, Dict, Iterator, List, Tuple

import pytest

from .board import Board
from .sim import BOARDS, SimBoard, SimError, SimRobot

DEFAULT_BOARD = "m32d"
#: The robot of `make demo-robot`: what orfa_sim_robot runs without a marker.
DEFAULT_SLAVES = (("m128s", 0x10), ("m32d", 0x12))
#: SimBoard options a fixture sets unless the marker does.
DEFAULTS = {"control": True, "trace": False}


def pytest_addoption(parser) -> None:
    group = parser.getgroup("orfa", "ORFA simulated boards")
    group.addoption("--orfa-board", choices=BOARDS, default=None,
                    help="board of orfa_sim_board and gateway of orfa_sim_robot"
                         " when a test does not say (default %s)" % DEFAULT_BOARD)


def pytest_configure(config) -> None:
    config.addinivalue_line(
        "markers", "orfa_board(board, **options): the board and SimBoard options of"
                   " the orfa_sim_board fixture")
    config.addinivalue_line(
        "markers", "orfa_robot(gateway=..., slaves=[(board, addr[, elf])], **options):"
                   " the robot of the orfa_sim_robot fixture")


def _default_board(request) -> str:
    # getoption's default covers a plugin loaded after the command line was
    # parsed (pytest_plugins in a test module)
    return request.config.getoption("orfa_board", default=None) or DEFAULT_BOARD


def _marker(request, name: str) -> Tuple[Tuple[Any, ...], Dict[str, Any]]:
    marker = request.node.get_closest_marker(name)
    return (tuple(marker.args), dict(marker.kwargs)) if marker else ((), {})


def _check_board(board: Any, where: str) -> str:
    if board not in BOARDS:
        pytest.fail("%s: board %r is not one of %s" % (where, board, ", ".join(BOARDS)),
                    pytrace=False)
    return board


def _slaves(specs: Any) -> List[Tuple[str, int, Any]]:
    """[(board, addr) or (board, addr, elf)] -> SimRobot's slave specs."""
    out = []
    for spec in specs:
        if not isinstance(spec, (tuple, list)) or len(spec) not in (2, 3) \
                or not isinstance(spec[1], int):
            pytest.fail("orfa_robot: slave %r is not (board, addr) or (board, addr, elf)"
                        % (spec,), pytrace=False)
        _check_board(spec[0], "orfa_robot slave")
        out.append((spec[0], spec[1], spec[2] if len(spec) == 3 else None))
    return out


def _check_options(options: Dict[str, Any], where: str) -> None:
    known = [name for name in inspect.signature(SimBoard).parameters
             if name not in ("board", "slaves")]
    unknown = sorted(set(options) - set(known))
    if unknown:
        pytest.fail("%s: no SimBoard option %s (options: %s)"
                    % (where, ", ".join(unknown), ", ".join(known)), pytrace=False)


def _run(make) -> Iterator[SimBoard]:
    """Start what make() builds, hand it to the test, stop it after."""
    error = None
    try:
        sim = make()
        sim.start()
    except (SimError, ValueError, TypeError) as exc:
        error = "orfa: %s" % exc
    if error is not None:               # outside the except: no chained traceback
        pytest.fail(error, pytrace=False)
    try:
        yield sim
    finally:
        status = sim.stop()
    # SIGTERM ends a healthy simulator with 0; 1 is a crashed firmware
    if status not in (None, 0):
        pytest.fail("orfa: orfa-sim exited with %d: %s"
                    % (status, sim.final_stderr.strip() or "(no message)"), pytrace=False)


@pytest.fixture
def orfa_sim_board(request) -> Iterator[SimBoard]:
    """A started SimBoard (control socket on): `.port`, `.gateway()`,
    `.control`, `.wait_s()`. Board and options: an indirect parameter (a
    board name), `@pytest.mark.orfa_board(board, **options)`, `--orfa-board`."""
    args, options = _marker(request, "orfa_board")
    if len(args) > 1:
        pytest.fail("orfa_board takes one board and SimBoard options, not %r" % (args,),
                    pytrace=False)
    board = getattr(request, "param", None) or (args[0] if args else _default_board(request))
    _check_board(board, "orfa_board")
    _check_options(options, "orfa_board")
    yield from _run(lambda: SimBoard(board, **dict(DEFAULTS, **options)))


@pytest.fixture
def orfa_sim_robot(request) -> Iterator[SimRobot]:
    """A started SimRobot: a gateway board and slave boards on one I2C bus
    (the control socket reaches each: `.control.slave(0x10)`). Set by
    `@pytest.mark.orfa_robot(gateway="m32d", slaves=[("m128s", 0x10)], **options)`;
    without a marker the gateway is `--orfa-board`'s with DEFAULT_SLAVES."""
    args, options = _marker(request, "orfa_robot")
    if args:
        pytest.fail("orfa_robot takes keywords (gateway=, slaves=, SimBoard options),"
                    " not %r" % (args,), pytrace=False)
    gateway = options.pop("gateway", None) or _default_board(request)
    _check_board(gateway, "orfa_robot gateway")
    slaves = _slaves(options.pop("slaves", DEFAULT_SLAVES))
    _check_options(options, "orfa_robot")
    yield from _run(lambda: SimRobot(gateway, slaves=slaves, **dict(DEFAULTS, **options)))


# --- typed API ------------------------------------------------------------------
@pytest.fixture
def orfa_board(orfa_sim_board):
    """A Board (orfa.board, the typed API) on orfa_sim_board's own drivers:
    `orfa_board.servo.set_width(3, 1500)`; its gateway is closed after."""
    with orfa_sim_board.gateway() as gw:
        yield Board(gw)


@pytest.fixture
def orfa_robot_boards(orfa_sim_robot):
    """{address: Board} of orfa_sim_robot: the gateway's own (its local
    address, 0xAA) and each slave's, all on one serial link."""
    with orfa_sim_robot.gateway() as gw:
        boards = {gw.local: Board(gw)}
        for spec in orfa_sim_robot.slaves:
            boards[spec[1]] = Board(gw, spec[1])
        yield boards
