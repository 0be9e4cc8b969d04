"""`orfa` on a terminal: the console's readline and history file, the live
ADC table redrawn in place and ended by Ctrl-C, a port that vanishes."""

import os
import pty
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import require_builds
from orfa.sim import SimBoard

HOST = str(Path(__file__).resolve().parents[2] / "host")


@pytest.fixture(scope="module")
def sim():
    require_builds(["m32d"])
    with SimBoard("m32d", eeproms=(0xA0,), trace=False, adc={7: 1000}) as board:
        yield board


def spawn(args, env=None):
    """`python3 -m orfa ARGS` with stdin, stdout and stderr on a pty; (proc, master fd)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([sys.executable, "-m", "orfa"] + list(args),
                            stdin=slave, stdout=slave, stderr=slave, start_new_session=True,
                            env=dict(os.environ, PYTHONPATH=HOST, **(env or {})))
    os.close(slave)
    return proc, master


def read_until(fd, text, timeout=30.0):
    """What the pty shows until `text` appears (AssertionError after timeout)."""
    out = b""
    deadline = time.monotonic() + timeout
    while text.encode() not in out:
        left = deadline - time.monotonic()
        assert left > 0, "no %r in %r" % (text, out)
        if select.select([fd], [], [], left)[0]:
            try:
                chunk = os.read(fd, 4096)
            except OSError:
                break
            if not chunk:
                break
            out += chunk
    return out.decode(errors="replace")


def finish(proc, fd):
    try:
        return proc.wait(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(fd)


def test_console_with_readline_and_history(sim, tmp_path):
    history = tmp_path / "history"
    proc, fd = spawn(["--port", sim.port, "console"], env={"ORFA_HISTORY": str(history)})
    read_until(fd, "orfa> ")
    os.write(fd, b"V\n")
    assert "V1.1" in read_until(fd, "V1.1")
    os.write(fd, b"S A0 P\n")
    read_until(fd, "SWP")
    os.write(fd, b"#" + b"x" * 150 + b"\n")
    os.write(fd, b"L\n")
    read_until(fd, "LAA\r\norfa> ")
    os.write(fd, b"\x04")                         # Ctrl-D
    assert finish(proc, fd) == 0
    assert history.read_text().splitlines()[-4:] == ["V", "S A0 P", "#" + "x" * 150, "L"]


def test_console_ctrl_c_ends_it(sim):
    proc, fd = spawn(["--port", sim.port, "console"], env={"ORFA_HISTORY": os.devnull})
    read_until(fd, "orfa> ")
    # CPython's readline sees a SIGINT that lands between the prompt and its
    # select() only at the next signal: send again until it ends
    for _ in range(10):
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=2)
            break
        except subprocess.TimeoutExpired:
            pass
    assert finish(proc, fd) == 0


def test_adc_watch_redraws_in_place_until_ctrl_c(sim):
    proc, fd = spawn(["--port", sim.port, "adc", "--channels", "7", "--watch", "0.05"])
    shown = read_until(fd, "7   204  0.996")
    shown += read_until(fd, "\x1b[10A\x1b[J")            # up over the 10 lines, clear
    os.killpg(proc.pid, signal.SIGINT)
    assert finish(proc, fd) == 0
    assert "Traceback" not in shown


def test_a_port_that_vanishes_is_one_line_and_exit_1():
    require_builds(["m32d"])
    board = SimBoard("m32d", trace=False).start()
    proc = subprocess.Popen([sys.executable, "-m", "orfa", "--port", board.port, "console"],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=dict(os.environ, PYTHONPATH=HOST))
    try:
        proc.stdin.write("V\n")
        proc.stdin.flush()
        assert proc.stdout.readline() == "V1.1\n"
        port = board.port
        board.stop()
        out, err = proc.communicate("V\n", timeout=30)
        assert (proc.returncode, out) == (1, "")
        assert err == "orfa: %s: [Errno 5] Input/output error\n" % port
    finally:
        board.stop()
        if proc.poll() is None:
            proc.kill()
            proc.wait()
