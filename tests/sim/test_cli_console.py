"""`orfa console` and `make demo` as a person meets them: ERROR replies
explained, a local help, a CR inside a line is a request's end, a quiet
`make demo` that labels the port and ends on Ctrl-C without make's noise."""

import os
import pty
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from orfa.cli import console as cli_console
from orfa.sim import BUILD_HINT, missing_builds

ROOT = Path(__file__).resolve().parents[2]
ENV = dict(os.environ, PYTHONPATH=str(ROOT / "host"))


def require_builds(boards):
    missing = missing_builds(boards)
    if missing:
        pytest.fail("missing %s: %s" % (", ".join(map(str, missing)), BUILD_HINT),
                    pytrace=False)


def console(text, *args):  # noqa: F811 (the module is cli_console)
    require_builds(["m32d"])
    return subprocess.run([sys.executable, "-m", "orfa", "--sim", "m32d"] + list(args)
                          + ["console"], env=ENV, input=text, capture_output=True,
                          text=True, timeout=60)


def test_console_explains_error_codes_as_request_does():
    r = console("S 42 P\nV\n")
    assert (r.returncode, r.stdout) == (0, "ERROR 06\nV1.1\n"), r.stderr
    request = subprocess.run([sys.executable, "-m", "orfa", "--sim", "m32d", "request",
                              "S 42 P"], env=ENV, capture_output=True, text=True, timeout=60)
    assert r.stderr == request.stderr == (
        "orfa: S 42 P: ERROR 06: no ACK for an address byte (no device, bus not to be had,"
        " register not readable)\n")


def test_console_explains_every_error():
    r = console("S 42 P\nS AA 0\nQ\n")
    assert r.stdout == "ERROR 06\nERROR 03\nERROR 02\n"
    lines = r.stderr.splitlines()
    assert [line.split(": ")[1:3] for line in lines] == [
        ["S 42 P", "ERROR 06"], ["S AA 0", "ERROR 03"], ["Q", "ERROR 02"]], r.stderr
    assert all(line.count(": ") == 3 for line in lines), r.stderr     # code: meaning


def test_console_answers_help_itself():
    r = console("help\n?\n  HELP \nV\n")
    assert r.returncode == 0, r.stderr
    help_text = cli_console.HELP
    assert r.stdout == (help_text + "\n") * 3 + "V1.1\n"
    assert r.stderr == ""
    assert "S A0 10 S A1 02 P" in help_text and "Ctrl-D" in help_text


def test_a_cr_inside_a_line_ends_a_request():
    """`printf 'V\\rS 42 P\\nL\\nC\\n' | orfa console`: the board takes the CR as
    a line end, so four requests, four replies, in step."""
    r = console("V\rS 42 P\nL\nC\n# a comment\r\nV\r\n")
    assert r.returncode == 0, r.stderr
    assert r.stdout == "V1.1\nERROR 06\nLAA\nC0063\nV1.1\n"


def test_sim_terminal_labels_its_paths(tmp_path):
    require_builds(["m32d"])
    r = subprocess.run([sys.executable, "-m", "orfa", "sim", "--board", "m32d", "--control",
                        str(tmp_path / "ctl"), "--terminal"], env=ENV, input="V\n",
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("serial port:    /") and lines[0].endswith("/tty"), lines
    assert lines[1] == "control socket: %s" % (tmp_path / "ctl")
    assert lines[2:] == ["V1.1"]


class Pty:
    """A program on a pseudo-terminal, as a person at a terminal runs it."""

    def __init__(self, argv, cwd, env):
        self.pid, self.fd = pty.fork()
        if self.pid == 0:                                   # the child
            try:
                os.chdir(cwd)
                os.execvpe(argv[0], argv, env)
            finally:
                os._exit(127)
        self.out = b""

    def read_until(self, done, timeout):
        deadline = time.monotonic() + timeout
        while not done(self.out) and time.monotonic() < deadline:
            ready, _, _ = select.select([self.fd], [], [], 0.1)
            if ready:
                try:
                    data = os.read(self.fd, 4096)
                except OSError:                             # EIO: every writer is gone
                    break
                if not data:
                    break
                self.out += data
        return done(self.out)

    def write(self, data):
        os.write(self.fd, data)

    def wait(self, timeout):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                os.close(self.fd)
                return status
            self.read_until(lambda out: False, 0.1)
        os.kill(self.pid, signal.SIGKILL)
        os.waitpid(self.pid, 0)
        os.close(self.fd)
        raise AssertionError("still running: %r" % self.out)


def make_demo(*variables):
    """`make demo` on a pseudo-terminal, at its first prompt (-o setup:
    tools/setup.sh is not these tests' business)."""
    require_builds(["m32d"])
    # as a person's shell runs it: not as a sub-make of `make test` (make
    # would print "Entering directory" for a MAKELEVEL above 0)
    env = {k: v for k, v in ENV.items() if k not in ("MAKELEVEL", "MAKEFLAGS", "MFLAGS")}
    term = Pty(["make", "-o", "setup", "demo"] + list(variables), ROOT, env)
    if not term.read_until(lambda out: b"orfa> " in out, 300):
        term.wait(1)
    return term


def test_make_demo_is_quiet_and_labels_the_port(tmp_path):
    """`make demo` from scratch (BUILD= puts a fresh firmware build in
    tmp_path): no compiler lines, no make chatter before the prompt, the
    port's path with its label."""
    term = make_demo("BUILD=%s" % (tmp_path / "gate"))
    try:
        assert (tmp_path / "gate" / "orfa.elf").is_file()      # it did build
        before = term.out.decode(errors="replace").split("orfa> ")[0]
        assert before.count("\n") == 1 and before.startswith("serial port:    /"), before
        assert before.rstrip().endswith("/tty"), before
        term.write(b"V\r")
        # Ctrl-D as a person types it: at the next prompt (readline prints it
        # once the terminal is its own; an EOF typed before is the line
        # discipline's and lost, as on any terminal)
        assert term.read_until(lambda out: b"V1.1\r\norfa> " in out, 30), term.out
    finally:
        term.write(b"\x04")                                    # Ctrl-D: the end
        term.wait(30)


@pytest.mark.parametrize("target", ["demo", "demo-robot"])
@pytest.mark.parametrize("baud, line", [("460800", "--baud 460800"), ("230400", "--baud 230400"),
                                        ("auto", "--autobaud"), ("115200", "--baud 115200")])
def test_make_demo_talks_at_the_rate_it_builds(target, baud, line):
    """`make demo BAUD=460800` builds the 460800 gateway and its console
    talks at 460800 (BAUD=auto: the autobaud build, the console's
    preamble first); it built one rate and opened the console at 115200."""
    r = subprocess.run(["make", "-n", "-o", "setup", target, "BAUD=" + baud], cwd=ROOT,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    sim = [l for l in r.stdout.replace("\\\n", " ").splitlines() if "-m orfa sim " in l]
    assert len(sim) == 1 and sim[0].endswith(" %s --terminal" % line), r.stdout


def test_make_demo_at_460800_answers():
    term = make_demo("BAUD=460800")
    try:
        term.write(b"S AA 00 00 S AB 01 P\r")
        assert term.read_until(lambda out: b"SWAASR07P\r\norfa> " in out, 30), term.out
    finally:
        term.write(b"\x04")
        term.wait(30)


def test_make_demo_ends_on_ctrl_c_without_makes_interrupt_line():
    term = make_demo()
    term.write(b"V\r")
    assert term.read_until(lambda out: out.count(b"orfa> ") == 2, 30), term.out
    time.sleep(0.3)                                            # at the prompt again
    term.write(b"\x03")
    status = term.wait(30)
    text = term.out.decode(errors="replace")
    assert "V1.1" in text
    assert "Interrupt" not in text and "make:" not in text and "***" not in text, text
    assert os.WIFEXITED(status) or os.WTERMSIG(status) == signal.SIGINT, status


def test_console_on_a_silent_port_says_so_per_request_and_goes_on():
    """No board behind the port (a pty nobody answers): each request gets
    one `host:` line within the timeout, the console reads on, exit 0."""
    master, slave = pty.openpty()
    try:
        path = os.ttyname(slave)
        r = subprocess.run([sys.executable, "-m", "orfa", "--port", path, "--timeout", "0.3",
                            "console"], env=ENV, input="V\nL\n", capture_output=True,
                           text=True, timeout=30)
    finally:
        os.close(master)
        os.close(slave)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(lines) == 2 and all(line.startswith("host: ") for line in lines), r.stdout
    assert "Traceback" not in r.stderr
