"""What the host library does with a line that carries more than an ORFA
board's replies, against scripted lines (fake_line): every call returns or
raises an OrfaError within its timeout, whatever talks on the line; the
opening sync that ends a partial line the board holds; low-latency mode
for real ports. On simulated boards: tests/sim/test_open_sync.py."""

import threading
import time

import pytest

from fake_line import TALKS, ChattyLine, FakeLine
from orfa import Board, Gateway, OrfaError, Read, ReplyTimeout
from test_api_requests import board_answers, echo_answers

#: The gateway's timeout in these tests, and how much later than it a call
#: may end (scheduling on a loaded machine); twice the timeout is too late.
TIMEOUT = 0.3
SLACK = 0.25


def ends_in_time(call, limit=TIMEOUT + SLACK):
    """Run call() in a thread; it must return or raise an OrfaError within
    `limit` seconds (a call that hangs is left running: a daemon thread)."""
    done = {}

    def target():
        try:
            done["result"] = call()
        except BaseException as e:              # noqa: B902 (handed to the test)
            done["error"] = e
        done["elapsed"] = time.monotonic() - t0
    t0 = time.monotonic()
    worker = threading.Thread(target=target, daemon=True)
    worker.start()
    worker.join(limit + 2.0)
    assert not worker.is_alive(), "still running after %.1f s" % (limit + 2.0)
    assert done["elapsed"] <= limit, "ended after %.2f s, the limit is %.2f s" % (
        done["elapsed"], limit)
    error = done.get("error")
    assert error is None or isinstance(error, OrfaError), repr(error)
    if error is not None:
        assert "\n" not in str(error), str(error)
    return done


@pytest.fixture
def chatty(monkeypatch):
    """chatty(talk, chatty=True) -> (Gateway, ChattyLine): an M32-D gateway
    on a line that also carries TALKS[talk] (from the start, or once the
    test sets line.chatty)."""
    def make(talk, chatty=True):
        source, echo, board = TALKS[talk]
        line = ChattyLine(board_answers("m32d", table={"C": "C0063", "SA0P": "SWP"}),
                          source(), chatty=chatty, echo=echo, board=board)
        line.timeout = TIMEOUT
        monkeypatch.setattr("orfa.gateway.serial.serial_for_url", lambda url, **kw: line)
        return Gateway("fake://", timeout=TIMEOUT), line
    return make


CALLS = {
    "run": lambda gw: gw.run(["V", "SA0P", "SAA01SAB01P"]),
    "transactions": lambda gw: gw.transactions([[Read(0xA1, 2)], [Read(0xA1, 1)]]),
    "scan": lambda gw: gw.scan(0x50, 0x57),
    "resync": lambda gw: gw.resync(),
    "in_step": lambda gw: gw.in_step(),
    "version": lambda gw: gw.version(),
    "drivers": lambda gw: Board(gw).drivers,
    "client": lambda gw: gw.board().servo.widths(0, 4),
}


@pytest.mark.parametrize("call", sorted(CALLS))
@pytest.mark.parametrize("talk", sorted(TALKS))
def test_a_call_on_a_talking_line_ends_in_time(chatty, talk, call):
    """The line talks from the moment it is opened."""
    gw, _ = chatty(talk)
    ends_in_time(lambda: CALLS[call](gw))


@pytest.mark.parametrize("call", sorted(CALLS))
@pytest.mark.parametrize("talk", sorted(TALKS))
def test_a_call_after_the_line_starts_talking_ends_in_time(chatty, talk, call):
    """The board answered (opening sync, introspection), then the line
    starts to talk: resync() and the sorting-out after noise used to wait
    for a V1.1 with no deadline."""
    gw, line = chatty(talk, chatty=False)
    board = gw.board()
    assert board.drivers and gw.version() == "1.1"
    line.chatty = True
    ends_in_time(lambda: CALLS[call](gw))


def test_resync_on_a_talking_line_says_what_it_saw(chatty):
    gw, line = chatty("nmea", chatty=False)
    gw.version()
    line.chatty = True
    with pytest.raises(ReplyTimeout, match=r"^no V1\.1 .*within 0\.3 s.*\$GP"):
        gw.resync()


def test_a_reply_wait_shorter_than_the_port_timeout_keeps_its_own():
    """read_reply(timeout) on a silent line: its own deadline, not the
    port's (loop:// with a 2 s timeout)."""
    with Gateway("loop://", timeout=2.0) as gw:
        t0 = time.monotonic()
        with pytest.raises(ReplyTimeout):
            gw.read_reply(timeout=0.1)
        assert time.monotonic() - t0 < 0.6
        assert gw.serial.timeout == 2.0


# --- the opening sync -----------------------------------------------------------------

@pytest.fixture
def fake(monkeypatch):
    def make(answer=None, **kw):
        answer = answer or partial_answers
        line = FakeLine(answer)
        monkeypatch.setattr("orfa.gateway.serial.serial_for_url", lambda url, **k: line)
        return Gateway("fake://", timeout=0.2, **kw), line
    return make


def partial_answers(line):
    """echo_answers and C, plus the firmware's replies to the lines a
    partial one becomes."""
    if line == "C":
        return "C0063"
    if line.startswith("S AA 0"):
        return "ERROR 03"
    if line.startswith("V") and line != "V":
        return "ERROR 04"
    return echo_answers(line)


@pytest.mark.parametrize("partial", [b"S AA 0", b"\x00\x00\xf0", b"V", b"SA0P", b"# note"])
def test_the_first_request_is_answered_as_itself(fake, partial):
    """The board holds a partial line (a terminal's `S AA 0` without its
    Enter, a 9600-baud program's bytes): the gateway first ends it with a
    character no request may hold and a CR, so it is refused, never run,
    and drops every line up to the replies of a V and a C."""
    gw, line = fake(partial_answers)
    line._partial = partial
    assert gw.request("V") == "V1.1"
    assert gw.request("SA101P") == "SR01P"
    assert line.written[-5:] == [partial.decode("ascii", "replace") + "!", "V", "C", "V",
                                 "SA101P"]
    assert "SA0P" not in line.written                   # the partial write never ran


def test_the_opening_sync_drops_stale_replies(fake):
    gw, line = fake(partial_answers)
    line._out += b"SWAAP\r\nV1.1\r\nERROR 02\r\n"         # a previous program's replies
    assert gw.run(["SA102P"]) == ["SR0202P"]
    assert line.written == ["!", "V", "C", "SA102P"]


def test_the_opening_sync_is_done_once(fake):
    gw, line = fake()
    gw.version()
    gw.version()
    gw.resync()
    assert line.written == ["!", "V", "C", "V", "V", "V"]


def test_no_opening_sync_when_asked(fake):
    gw, line = fake(sync=False)
    gw.version()
    assert line.written == ["V"]


def test_a_silent_line_fails_the_sync_in_time_and_it_is_tried_again(fake):
    gw, line = fake(lambda l: None)
    ends_in_time(gw.version, limit=0.2 + SLACK)
    with pytest.raises(ReplyTimeout):
        gw.version()
    assert line.written.count("!") == 2


def test_the_autobaud_preamble_goes_before_the_sync(fake):
    gw, line = fake(autobaud=True, wait=lambda s: None)
    gw.version()
    assert line.written[:8] == [""] * 8 and line.written[8:] == ["!", "V", "C", "V"]


# --- low-latency mode ---------------------------------------------------------------------

class Port(FakeLine):
    """A FakeLine with pyserial's Linux call for the low-latency flag."""

    def __init__(self, refuse=None):
        super().__init__(partial_answers)
        self.refuse = refuse
        self.low_latency = []

    def set_low_latency_mode(self, on):
        self.low_latency.append(on)
        if self.refuse is not None:
            raise self.refuse


@pytest.mark.parametrize("refuse", [None, ValueError("Failed to update ASYNC_LOW_LATENCY"
                                                     " flag to True: [Errno 25]"),
                                    OSError(25, "Inappropriate ioctl for device")])
def test_a_real_port_opens_in_low_latency_mode(monkeypatch, refuse):
    """pyserial's set_low_latency_mode(True) where the port has it (Linux);
    a port that refuses it (a pty) opens all the same, quietly."""
    port = Port(refuse)
    monkeypatch.setattr("orfa.gateway.serial.serial_for_url", lambda url, **kw: port)
    gw = Gateway("/dev/ttyUSB0")
    assert port.low_latency == [True]
    assert gw.version() == "1.1"


def test_a_port_without_the_call_opens(fake):
    gw, line = fake()                                   # no set_low_latency_mode
    assert gw.version() == "1.1"
