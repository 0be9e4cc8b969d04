"""`orfa dash` without a simulator: the controls' checks on a scripted
gateway (fake_line.FakeLine: a bad value never reaches the line, a good
one sends exactly the typed API's request), the Flask app's endpoints and
stream with its test client, and the command line's errors. The page in a
browser against a simulated robot: tests/sim/test_dash.py."""

import json

import pytest

from fake_line import FakeLine
from orfa import Gateway, PinBusyError, ReplyTimeout, SerialError, boardmap
from orfa.cli import main
from orfa.dash.live import ControlError, Dashboard, NotFound, Refused
from test_api_requests import board_answers

flask = pytest.importorskip("flask", reason="orfa dash needs Flask (pip install 'orfa[dash]')")
from orfa.dash.web import _hosts, create_app  # noqa: E402

M32D = boardmap.load("m32d")
LOCAL = "%02X" % M32D.local_address


@pytest.fixture
def dash(monkeypatch):
    """A Dashboard of the gateway's own M32-D on a scripted line (no slaves);
    `dash.line` is the fake, emptied after discovery."""
    table = {"L": "L" + LOCAL, "SAA130306A4P": "SWAAAAP",
             # the ADC's RC: channel 0 on, AVCC, 10 bits; 0 and 1 asked, only 0 on
             "SAA0C0501P": "SWAAAP", "SAA0C0503P": "SWAAAP", "SAA0CSAB02P": "SWASR0501P"}
    line = FakeLine(board_answers("m32d", M32D.local_address, table))
    monkeypatch.setattr("orfa.gateway.serial.serial_for_url", lambda url, **kw: line)
    d = Dashboard(Gateway("fake://", timeout=0.2), slaves=())
    d.discover()
    del line.written[:]
    d.line = line
    return d


def test_discovery_describes_the_board_from_its_map(dash):
    assert list(dash.boards) == [LOCAL]
    info = dash.info[LOCAL]
    assert info["board"] == "m32d" and info["name"] == M32D.name and info["role"] == "gateway"
    assert info["drivers"] == [d.name for d in M32D.drivers]
    assert info["motors"] == 2 and info["gpio_ports"] == M32D.gpio_ports
    assert info["servo_pins"] == [p.label for p in sorted(M32D.pins_of("SERVO"),
                                                          key=lambda p: p.index)]
    assert info["pin_functions"]["PD5"] == ["MOTOR_PWM 0", "SERVO 14"]


def test_a_good_servo_control_sends_the_typed_apis_request(dash):
    assert dash.control(LOCAL, "servo", {"channel": 3, "us": 1700}) == \
        {"servo": 3, "us": 1700, "board": LOCAL}
    assert dash.line.written == ["SAA130306A4P"]
    # an angle is the manual's range: +30 degrees is 1700 us
    assert dash.control("0xaa", "servo", {"channel": 3, "angle": 30}) == \
        {"servo": 3, "us": 1700, "board": LOCAL}


@pytest.mark.parametrize("kind, body, message", [
    ("servo", {"channel": 3, "us": 99999},
     "servo: a width of 99999 us is outside 500..2500 (0: off)"),
    ("servo", {"channel": 3, "us": 499}, "servo: a width of 499 us is outside 500..2500 (0: off)"),
    ("servo", {"channel": 16, "us": 1500}, "servo: channel 16 is outside 0..15"),
    ("servo", {"channel": 3}, "servo: give us or angle (one of them)"),
    ("servo", {"channel": 3, "us": 1500, "angle": 3}, "servo: give us or angle (one of them)"),
    ("servo", {"channel": 3, "us": "1500"}, "servo: us must be an integer number, not '1500'"),
    ("servo", {"channel": 3, "us": 1500.5}, "servo: us must be an integer number, not 1500.5"),
    ("servo", {"channel": True, "us": 1500}, "servo: channel must be an integer number, not True"),
    ("servo", {"channel": 3, "angle": 80}, "servo: angle 80 is outside -75..75"),
    ("servo", {"us": 1500}, "servo: channel is missing"),
    ("servo", {"channel": 3, "us": 1500, "speed": 2},
     "servo: unknown field speed (fields: channel, us, angle)"),
    ("servo", [3, 1500], "servo: the body must be a JSON object"),
    ("motor", {"motor": 3, "duty": 10}, "motor: motor 3 is outside 1..2"),
    ("motor", {"motor": 1, "duty": -256}, "motor: duty -256 is outside -255..255"),
    ("motor", {"motor": 1, "duty": None}, "motor: duty must be an integer number, not null"),
    ("gpio", {"port": "E", "bit": 0, "level": 1},
     "gpio: port 'E': this board's ports are A, B, C, D"),
    ("gpio", {"port": "B", "bit": 8, "level": 1}, "gpio: bit 8 is outside 0..7"),
    ("gpio", {"port": "B", "bit": 2}, "gpio: give level (0 or 1), output (true or false) or both"),
    ("gpio", {"port": "B", "bit": 2, "level": 2}, "gpio: level 2 is outside 0..1"),
    ("gpio", {"port": "B", "bit": 2, "output": 1}, "gpio: output must be true or false, not 1"),
    ("adc", {"reference": "avcc"}, "adc: channels is missing (a list of 0..7, [] for none)"),
    ("adc", {"channels": 3}, "adc: channels must be a list of 0..7, not 3"),
    ("adc", {"channels": [8]}, "adc: channel 8 is outside 0..7"),
    ("adc", {"channels": ["1"]}, "adc: channel must be an integer number, not '1'"),
    ("adc", {"channels": [0], "reference": "vcc"},
     "adc: reference 'vcc': one of aref, avcc, internal"),
    ("adc", {"channels": [0], "bits": 12}, "adc: bits must be 8 or 10, not 12"),
    ("adc", {"channels": [0], "bits": True}, "adc: bits must be 8 or 10, not True"),
    ("adc", {"channels": [0], "rate": 1}, "adc: unknown field rate (fields: channels, reference,"
                                          " bits)"),
    ("servo", {"channel": 3, "us": "x" * 1000},
     "servo: us must be an integer number, not 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx..."),
])
def test_a_bad_control_is_refused_before_the_line(dash, kind, body, message):
    with pytest.raises(ControlError) as exc:
        dash.control(LOCAL, kind, body)
    assert str(exc.value) == message
    assert dash.line.written == []


def test_the_adc_control_configures_the_adc(dash):
    # the page can turn the ADC on: one write of RC, read back
    assert dash.control(LOCAL, "adc", {"channels": [0], "reference": "avcc", "bits": 10}) == \
        {"adc": [0], "reference": "avcc", "bits": 10, "board": LOCAL}
    assert dash.line.written == ["SAA0C0501P", "SAA0CSAB02P"]
    # a channel that did not turn on (its pin another function's) is named
    del dash.line.written[:]
    with pytest.raises(Refused) as exc:
        dash.control(LOCAL, "adc", {"channels": [1, 0, 1]})
    assert str(exc.value) == "adc: PA1 did not turn on: another function holds it"
    assert dash.line.written == ["SAA0C0503P", "SAA0CSAB02P"]


def test_an_unknown_board_or_control(dash):
    with pytest.raises(NotFound, match=r"no board at '10' here \(boards: AA\)"):
        dash.control("10", "servo", {"channel": 3, "us": 1500})
    with pytest.raises(NotFound, match=r"no control 'spi' \(controls: servo, motor, gpio, adc\)"):
        dash.control(LOCAL, "spi", {})
    assert dash.line.written == []


def test_a_board_that_fails_its_reading_shows_the_error(dash):
    # the scripted line answers nothing but introspection: the status read
    # gets ERROR 02, the board's card shows it, what it is stays
    snap = dash.poll()
    (board,) = snap["boards"]
    assert board["error"] == "ERROR 02: unknown command letter"
    assert board["name"] == M32D.name and "servo" not in board
    assert (snap["seq"], dash.poll()["seq"]) == (1, 2)


def test_subscribers_get_the_latest_snapshot_then_none_at_close(dash):
    first = dash.poll()
    q = dash.subscribe()
    assert q.get_nowait() is first
    second, third = dash.poll(), dash.poll()
    assert q.get_nowait() is third and second["seq"] == 2     # a slow reader skips
    dash.close()
    assert q.get_nowait() is None
    dash.unsubscribe(q)
    dash.poll()
    assert q.empty()


def test_a_signal_to_stop_is_no_board_error(dash, monkeypatch):
    # orfa dash stops on SIGTERM with a BaseException (as Ctrl-C's
    # KeyboardInterrupt is): the poller must let it through, not show it
    def interrupted(board):
        raise KeyboardInterrupt
    monkeypatch.setattr("orfa.dash.snapshot.read", interrupted)
    with pytest.raises(KeyboardInterrupt):
        dash.poll()
    assert dash.latest() is None


def test_the_interval_must_be_positive():
    with pytest.raises(ValueError, match="above 0 s"):
        Dashboard(None, interval=0)


# --- the web app ------------------------------------------------------------------

class StubDash:
    """What the app asks of a Dashboard, scripted."""

    def __init__(self, snap=None, outcome=None):
        self.snap, self.outcome = snap, outcome
        self.calls = []
        self.unsubscribed = False

    def latest(self):
        return self.snap

    def control(self, addr, kind, body):
        self.calls.append((addr, kind, body))
        if isinstance(self.outcome, BaseException):
            raise self.outcome
        return self.outcome

    def subscribe(self):
        import queue
        q = queue.Queue()
        q.put(self.snap)
        q.put(None)                  # the dashboard closes after one snapshot
        return q

    def unsubscribe(self, q):
        self.unsubscribed = True


SNAP = {"seq": 7, "time": 1.5, "interval": 0.2, "port": "fake://", "others": [],
        "boards": [{"addr": "AA", "servo": [{"ch": 0, "us": 1500, "deg": 0.0}]}]}


def client(listen=None, **kw):
    app = create_app(StubDash(**kw))
    if listen is not None:
        app.config["ORFA_HOSTS"] = _hosts(listen)       # as Server sets it
    return app.test_client()


@pytest.mark.parametrize("listen, host, status", [
    ("127.0.0.1", "127.0.0.1:8000", 200), ("127.0.0.1", "localhost:8000", 200),
    ("127.0.0.1", "[::1]:8000", 200), ("127.0.0.1", "LOCALHOST", 200),
    ("127.0.0.1", "evil.example:8000", 403), ("127.0.0.1", "127.0.0.1.evil.example", 403),
    ("robot.lan", "robot.lan:8000", 200), ("robot.lan", "evil.example", 403),
    ("0.0.0.0", "evil.example:8000", 200),        # every interface: any name
])
def test_only_the_served_names_are_answered(listen, host, status):
    # a page of another site whose name was rebound to 127.0.0.1 sends its
    # own name as Host: it gets neither the values nor the controls
    c = client(listen, snap=SNAP, outcome={"ok": 1})
    r = c.get("/api/snapshot", headers={"Host": host})
    assert r.status_code == status
    r = c.post("/api/AA/servo", json={"channel": 3, "us": 1700}, headers={"Host": host})
    assert r.status_code == status
    if status == 403:
        assert r.get_json()["error"].startswith("%s is not a name this dashboard" % host)


def test_the_page_and_its_files_are_served():
    c = client(snap=SNAP)
    page = c.get("/")
    assert page.status_code == 200 and b"<title>ORFA dashboard</title>" in page.data
    for name in (b"static/dash.js", b"static/dash.css"):
        assert name in page.data
        assert c.get("/" + name.decode()).status_code == 200
    # nothing from elsewhere: the page works offline
    assert b"http" not in page.data


def test_the_snapshot_endpoint():
    assert client(snap=SNAP).get("/api/snapshot").get_json() == SNAP
    r = client(snap=None).get("/api/snapshot")
    assert (r.status_code, r.get_json()) == (503, {"error": "no snapshot yet"})


def test_the_event_stream_sends_snapshots_as_json():
    stub = StubDash(snap=SNAP)
    r = create_app(stub).test_client().get("/events")
    assert r.status_code == 200 and r.mimetype == "text/event-stream"
    body = r.get_data(as_text=True)
    events = [e for e in body.split("\n\n") if e.startswith("event: snapshot")]
    assert len(events) == 1
    assert json.loads(events[0].split("\ndata: ", 1)[1]) == SNAP
    assert stub.unsubscribed


def test_a_control_posts_json_to_the_dashboard():
    stub = StubDash(outcome={"servo": 3, "us": 1700, "board": "AA"})
    r = create_app(stub).test_client().post("/api/AA/servo", json={"channel": 3, "us": 1700})
    assert (r.status_code, r.get_json()) == (200, {"servo": 3, "us": 1700, "board": "AA"})
    assert stub.calls == [("AA", "servo", {"channel": 3, "us": 1700})]


@pytest.mark.parametrize("outcome, status, error", [
    (ControlError("servo: channel 16 is outside 0..15"), 400, "servo: channel 16 is outside 0..15"),
    (NotFound("no board at '12' here (boards: AA)"), 404, "no board at '12' here (boards: AA)"),
    (Refused("PB0 did not change: another function holds it"), 409,
     "PB0 did not change: another function holds it"),
    (PinBusyError(3, 0xAA, "motor PWM1", "write"), 409,
     "0xAA motor PWM1: write refused: PIN_BUSY (a pin the operation needs belongs to"
     " another function)"),
    (ReplyTimeout("no reply to 'SAA13P' within 0.2 s"), 503,
     "the serial line: no reply to 'SAA13P' within 0.2 s"),
    # the line failed under the page: no board refused anything (a
    # SerialError is an OrfaError, as the board's refusals are)
    (SerialError("/dev/ttyUSB0: device reports readiness to read but returned no data"), 503,
     "the serial line: /dev/ttyUSB0: device reports readiness to read but returned no data"),
    (RuntimeError("a bug"), 500, "RuntimeError: a bug"),
])
def test_control_errors_are_one_line_of_json(outcome, status, error):
    r = client(outcome=outcome).post("/api/AA/servo", json={"channel": 3, "us": 1})
    assert (r.status_code, r.get_json()) == (status, {"error": error})


def test_requests_the_app_does_not_take():
    c = client(outcome={})
    r = c.post("/api/AA/servo", data="channel=3", content_type="text/plain")
    assert (r.status_code, r.get_json()) == (
        400, {"error": "servo: the body must be JSON (Content-Type: application/json)"})
    r = c.get("/api/AA/servo")
    assert (r.status_code, r.get_json()) == (405, {"error": "GET is not allowed on /api/AA/servo"})
    r = c.get("/nothing")
    assert (r.status_code, r.get_json()) == (404, {"error": "no such page: /nothing"})


@pytest.mark.parametrize("depth", [900, 990, 1000, 5000, 100000])
def test_a_deeply_nested_body_is_a_bad_request(dash, depth):
    # json gives up on deep nesting with a RecursionError, which is no
    # ValueError: the page gets 400 and one line, the board is not asked
    c = create_app(dash).test_client()
    for body in ("[" * depth + "]" * depth,
                 '{"channel": 3, "us": ' + "[" * depth + "]" * depth + "}"):
        r = c.post("/api/AA/servo", data=body, content_type="application/json")
        assert r.status_code == 400, r.get_json()
        error = r.get_json()["error"]
        assert error.startswith("servo: ") and "\n" not in error and len(error) < 200, error
    assert dash.line.written == []


def test_a_serial_line_that_fails_under_a_control_is_503(dash):
    # the real Dashboard on a line whose reads fail as a vanished USB
    # adapter's do: the Gateway's SerialError, answered as the docs say
    import serial

    def broken(*args, **kw):
        raise serial.SerialException("device reports readiness to read but returned no data")
    dash.line.read = dash.line.read_until = dash.line.readline = broken
    dash.line.write = broken
    r = create_app(dash).test_client().post("/api/AA/servo", json={"channel": 3, "us": 1700})
    assert r.status_code == 503, r.get_json()
    assert r.get_json()["error"].startswith("the serial line: fake://: ")


# --- the command line -------------------------------------------------------------

def test_without_flask_one_line_and_exit_2(monkeypatch, capsys):
    import importlib.util
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "flask" else real(name, *a))
    assert main(["dash", "--port", "loop://"]) == 2
    assert capsys.readouterr().err == "orfa: orfa dash needs Flask: pip install 'orfa[dash]'\n"


@pytest.mark.parametrize("argv, message", [
    (["dash", "--port", "loop://", "--listen", "localhost:http"], "HOST:PORT like 127.0.0.1:8000"),
    (["dash", "--port", "loop://", "--listen", "127.0.0.1:70000"], "port 0..65535"),
    (["dash", "--port", "loop://", "--interval", "0"], "seconds, 0.01..3600"),
    (["dash", "--port", "loop://", "--boards", "0x10,x"], "'x' is not a number"),
    (["dash", "--port", "loop://", "--boards", "0x10", "--no-scan"],
     "argument --no-scan: not allowed with argument --boards"),
])
def test_bad_options_exit_2(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_addr_does_not_apply(capsys):
    assert main(["dash", "--port", "loop://", "--addr", "0x10"]) == 2
    assert capsys.readouterr().err == \
        "orfa: dash shows every board on the bus: --addr does not apply\n"


def test_boards_are_addresses(capsys):
    assert main(["dash", "--port", "loop://", "--boards", "0x10,0x11"]) == 2
    assert capsys.readouterr().err == ("orfa: --boards 0x11: an 8-bit address is even,"
                                       " 0x00..0xFE (the 7-bit 0x11 is 0x22, or give --7bit)\n")


def test_listen_forms():
    from orfa.cli.dash import listen_spec
    assert listen_spec("0.0.0.0:8080") == ("0.0.0.0", 8080)
    assert listen_spec(":0") == ("127.0.0.1", 0)
    assert listen_spec("9000") == ("127.0.0.1", 9000)
    assert listen_spec("[::1]:8000") == ("::1", 8000)

