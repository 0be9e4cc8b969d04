"""`python3 -m orfa sim` and `python3 -m orfa request` against simulated boards."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from orfa.sim import BUILD_HINT, SimBoard, SimError, missing_builds

HOST = str(Path(__file__).resolve().parents[2] / "host")
ENV = dict(os.environ, PYTHONPATH=HOST)


def require_builds(boards):
    missing = missing_builds(boards)
    if missing:
        pytest.fail("missing %s: %s" % (", ".join(map(str, missing)), BUILD_HINT),
                    pytrace=False)


def orfa(*args, **kw):
    return subprocess.run([sys.executable, "-m", "orfa"] + list(args), env=ENV,
                          capture_output=True, text=True, timeout=60, **kw)


@pytest.mark.parametrize("board_name", ["m32d", "m128s"])
def test_request_command(board_name):
    require_builds([board_name])
    with SimBoard(board_name, eeproms=(0xA0,), trace=False) as sim:
        result = orfa("request", "--port", sim.port, "V", "S A0 P", "S A2 P")
        assert result.returncode == 1, result.stderr
        assert result.stdout == "V1.1\nSWP\nERROR 06\n"
        assert result.stderr == ("orfa: S A2 P: ERROR 06: no ACK for an address byte"
                                 " (no device, bus not to be had, register not readable)\n")


@pytest.mark.parametrize("rate", [230400, 460800])
def test_commands_at_the_fast_rates(rate):
    """`--baud` sets the port's rate: a gateway built for 230400 or 460800
    answers `orfa` at it, and says nothing to 115200."""
    from conftest import build_gateway
    require_builds(["m128s"])
    with SimBoard("m128s", firmware=build_gateway("m128s", rate), trace=False) as sim:
        result = orfa("request", "--port", sim.port, "--baud", str(rate),
                      "V", "S AA 00 00 S AB 01 P")
        assert (result.returncode, result.stdout, result.stderr) == (0, "V1.1\nSWAASR06P\n", "")
        result = orfa("--baud", str(rate), "version", "--port", sim.port)
        assert (result.returncode, result.stderr) == (0, "")
        assert result.stdout.startswith("protocol 1.1\nboard    m128s")
        result = orfa("version", "--port", sim.port, "--timeout", "0.5")
        assert result.returncode == 1 and result.stderr.startswith("orfa: no reply line")


@pytest.mark.parametrize("rate", [230400, 460800])
def test_sim_at_a_fast_rate_runs_the_gateway_built_for_it(rate):
    """`--sim B --baud R` and `orfa sim --baud R` simulate the board at R:
    its gateway built for that rate (orfa.locate.gateway_firmware), not the
    default build, which would say nothing to R."""
    require_builds(["m32d"])
    result = orfa("--sim", "m32d", "--baud", str(rate), "request", "V", "S AA 00 00 S AB 01 P")
    assert (result.returncode, result.stdout, result.stderr) == (0, "V1.1\nSWAASR07P\n", "")
    result = orfa("sim", "--board", "m128s", "--baud", str(rate), "--terminal", input="V\n")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[1:] == ["V1.1"]


def test_sim_at_a_rate_without_a_build_is_one_line():
    result = orfa("--sim", "m32d", "--baud", "921600", "version")
    assert (result.returncode, result.stdout) == (2, "")
    assert result.stderr.startswith("orfa: no m32d gateway at 921600 baud: BAUD=921600 is "
                                    "refused: a character lasts 80 cycles there")
    assert len(result.stderr.splitlines()) == 1


def test_request_refused_on_the_host():
    result = orfa("request", "--port", "loop://", "V" * 129)
    assert result.returncode == 1
    assert "limit is 128" in result.stderr


def test_terminal_through_a_pipe():
    require_builds(["m32d"])
    # make demo's console: a comment over 128 characters is what the board
    # ignores, not a traceback
    result = orfa("sim", "--board", "m32d", "--eeprom", "0xA0", "--terminal",
                  input="V\nl\n# comment\n\n#%s\nS A0 P\nS A2 P\nQ\n" % ("c" * 199))
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[1:] == ["V1.1", "LAA", "SWP", "ERROR 06", "ERROR 02"]
    label, port = lines[0].split(None, 2)[:2], lines[0].split()[-1]
    assert label == ["serial", "port:"] and port.endswith("/tty")
    assert not os.path.exists(port)              # the simulator has stopped


def test_sim_runs_until_interrupted():
    require_builds(["m32d"])
    proc = subprocess.Popen([sys.executable, "-m", "orfa", "sim", "--board", "m32d"],
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = proc.stdout.readline().strip()
        assert os.path.exists(port), proc.stderr.read() if proc.poll() is not None else port
        result = orfa("request", "--port", port, "C")
        assert result.stdout == "C0063\n"
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=10) == 0
        deadline = time.monotonic() + 5
        while os.path.exists(port) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not os.path.exists(port)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_bad_firmware_shows_the_simulators_stderr(tmp_path):
    require_builds([])
    elf = tmp_path / "bad.elf"
    elf.write_bytes(b"not an elf")
    with pytest.raises(SimError) as exc:
        SimBoard("m32d", firmware=elf, start_timeout=10).start()
    assert "exited with 2" in str(exc.value)
    assert "stderr: (empty)" not in str(exc.value)


def test_terminal_with_a_slave_board():
    require_builds(["m32d"])
    echo = Path(__file__).resolve().parents[2] / "build" / "sim-fw" / "twi_slave_echo.elf"
    if not echo.is_file():
        pytest.fail("missing %s: %s" % (echo, BUILD_HINT), pytrace=False)
    result = orfa("sim", "--board", "m32d", "--slave", "m32d:0x20:%s" % echo, "--terminal",
                  input="S 20 5A P\nS 21 01 P\n")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[1:] == ["SWAP", "SR5AP"]


def test_sim_refuses_a_bad_slave():
    result = orfa("sim", "--slave", "m32d:0x21")
    assert result.returncode == 2
    assert "BOARD:ADDR" in result.stderr or "even" in result.stderr


def test_terminal_with_autobaud_firmware():
    """`orfa sim --autobaud --baud R` opens the console with the preamble
    (its quiet in simulated time) on a BAUD=auto build."""
    from conftest import build_gateway
    require_builds(["m128s"])
    elf = build_gateway("m128s", "auto")
    result = orfa("sim", "--board", "m128s", "--firmware", str(elf), "--terminal",
                  "--baud", "14400", "--autobaud", input="V\nS AA 00 00 S AB 01 P\n")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[1:] == ["V1.1", "SWAASR06P"]


def test_sim_with_control_socket_and_trace(tmp_path):
    """`sim --control PATH` prints the socket's path on the second line and
    it reaches the board's control interface; --trace FILE keeps the trace;
    --adc sets an analog input; the link to the socket goes at exit."""
    from orfa.simctl import SimControl
    require_builds(["m32d"])
    control, trace = tmp_path / "ctl", tmp_path / "trace.log"
    proc = subprocess.Popen([sys.executable, "-m", "orfa", "sim", "--board", "m32d",
                             "--adc", "3=1200", "--control", str(control), "--trace", str(trace)],
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = proc.stdout.readline().strip()
        assert proc.stdout.readline().strip() == str(control)
        result = orfa("request", "--port", port, "V")
        assert result.stdout == "V1.1\n"
        with SimControl(str(control)) as ctl:
            assert ctl.pin("A3")[0] in (0, 1)
            assert ctl.request("adc 3") == "1200"
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=10) == 0
        assert not os.path.lexists(control)
        assert " uart rx 56" in trace.read_text()          # the V
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_sim_at_a_fast_rate_with_its_own_control_socket():
    """`orfa sim --baud 230400 --control` (no PATH: the simulator's own
    socket, docs/cli.md's example) prints the port, then the socket's path
    (it was a TypeError traceback: a Path added to a str); the board runs
    the 230400 build, `orfa --port P --baud 230400` talks to it, and the
    socket's `line` says both ends run at 230400 (UBRR 1)."""
    from orfa.simctl import SimControl
    require_builds(["m32d"])
    proc = subprocess.Popen([sys.executable, "-m", "orfa", "sim", "--baud", "230400", "--control"],
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = proc.stdout.readline().strip()
        control = proc.stdout.readline().strip()
        assert os.path.exists(port) and os.path.exists(control), \
            (port, control, proc.stderr.read() if proc.poll() is not None else "")
        result = orfa("request", "--port", port, "--baud", "230400", "V", "S AA 00 00 S AB 01 P")
        assert (result.returncode, result.stdout, result.stderr) == (0, "V1.1\nSWAASR07P\n", "")
        with SimControl(control) as ctl:
            assert ctl.request("line").split()[:6] == ["pc", "230400", "bit", "32", "board", "32"]
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=10) == 0
        assert proc.stderr.read() == ""
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


@pytest.mark.parametrize("board, rate", [("m32d", 460800), ("m128s", 230400)])
def test_autobaud_runs_the_autobaud_build(board, rate):
    """`--autobaud` with a simulated board runs its BAUD=auto gateway
    (build/<board>-gate-auto/), which finds the rate from the preamble: it
    ran the fixed --baud build, which ignores the CRs, so nothing of
    autobaud was tried. `orfa sim --autobaud` likewise: before the
    preamble the board's receiver is off (it times the pin)."""
    from orfa.simctl import SimControl
    require_builds([board])
    result = orfa("--sim", board, "--baud", str(rate), "--autobaud", "request", "V",
                  "S AA 00 00 S AB 01 P")
    assert (result.returncode, result.stdout, result.stderr) == \
        (0, "V1.1\nSWAASR%02XP\n" % {"m32d": 7, "m128s": 6}[board], "")
    proc = subprocess.Popen([sys.executable, "-m", "orfa", "sim", "--board", board, "--baud",
                             str(rate), "--autobaud", "--control"],
                            env=ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        proc.stdout.readline()
        with SimControl(proc.stdout.readline().strip()) as ctl:
            assert ctl.line()["rxen"] == 0
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=10) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


@pytest.mark.parametrize("rate", ["921600", "12345"])
def test_autobaud_refuses_a_rate_it_does_not_find(rate):
    """A rate the BAUD=auto build does not detect is one line, exit 2, at
    once (it waited out --timeout for a reply that could not come)."""
    require_builds(["m32d"])
    for args in (["--sim", "m32d", "--baud", rate, "--autobaud", "version"],
                 ["sim", "--baud", rate, "--autobaud"]):
        result = orfa(*args)
        assert (result.returncode, result.stdout, result.stderr) == \
            (2, "", "orfa: no m32d gateway finds %s baud: BAUD=auto detects 2400 4800 9600"
             " 14400 19200 28800 38400 57600 76800 115200 230400 460800\n" % rate)


def test_sim_board_for_one_command():
    """What a new user types first: `orfa --sim m32d scan` shows the gateway
    itself (0x55 in the 7-bit grid); devices come with the sim options."""
    require_builds(["m32d"])
    result = orfa("--sim", "m32d", "--eeprom", "0xA0", "scan")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[6] == "50: 50 -- -- -- -- 55 -- -- -- -- -- -- -- -- -- --"
    assert lines[-1] == "8-bit: 0xA0 0xAA (0xAA: the gateway itself)"
    assert sum(line.count("--") for line in lines) == 0x70 - 2
