"""The typed API (orfa.board, orfa.clients) and Gateway.run on a scripted
gateway (fake_line.FakeLine): the exact requests each call sends, what the
replies become, refusals with the status register's reason, the flow rule,
noise and timeouts. The simulated boards: tests/sim/test_board_api.py."""

import pytest

from fake_line import FakeLine, synced_gateway
from orfa import (AddressNackError, BadValueError, Board, DataNackError, Gateway,
                  LimitError, NoDriverError, OrfaError, PinBusyError, ProtocolError,
                  RegisterError, ReplyTimeout, SerialError, ServoRange, Status)
from orfa import errors, flow
from orfa.board import boardmap


def records_hex(board):
    m = boardmap.load(board)
    return b"".join(bytes([d.uid >> 8, d.uid & 0xFF, d.major, d.minor, d.start, d.count])
                    for d in m.drivers).hex().upper(), len(m.drivers)


def board_answers(board="m32d", addr=0xAA, table=()):
    """Answers of a board at addr: its introspection (from the map), the
    V marker, the clock, and `table` (request -> reply); anything else ERROR 02."""
    recs, n = records_hex(board)
    w, r = "%02X" % addr, "%02X" % (addr | 1)
    answers = {"S%s0000S%s01P" % (w, r): "SWAASR%02XP" % n,
               "S%s0001S%s%02XP" % (w, r, len(recs) // 2): "SWAASR%sP" % recs,
               "V": "V1.1", "C": "C0063"}
    answers.update(dict(table))
    return lambda line: answers.get(line, "ERROR 02")


@pytest.fixture
def fake(monkeypatch):
    """fake(answer) -> (Gateway, FakeLine): a Gateway whose port is the fake,
    its opening sync done (tests/host/test_line_contents.py) and left out
    of line.written."""
    def make(answer):
        line = FakeLine(lambda text: "C0063" if text == "C" else answer(text))
        return synced_gateway(monkeypatch, line), line
    return make


def make_board(fake, board="m32d", addr=None, table=()):
    gw, line = fake(board_answers(board, 0xAA if addr is None else addr, table))
    b = Board(gw, addr)
    b.drivers                                          # introspection, then the test's requests
    del line.written[:]
    return b, line


# --- introspection ------------------------------------------------------------------

@pytest.mark.parametrize("board, sp", [("m32d", 0x13), ("m128s", 0x0B)])
def test_registers_from_introspection(fake, board, sp):
    b, _ = make_board(fake, board)
    assert b.map.board == board
    assert b.register("servo", "SP") == sp             # docs/registers.md
    assert b.addr == 0xAA and b.is_local


def test_missing_driver(fake):
    b, line = make_board(fake, "m128s")
    assert not b.has("motor") and b.has("servo")
    with pytest.raises(NoDriverError, match="0xAA has no motor driver"):
        b.motor
    assert isinstance(NoDriverError("x"), OrfaError)
    assert line.written == []


def test_absent_slave(fake):
    gw, _ = fake(lambda line: "V1.1" if line == "V" else "ERROR 06")
    with pytest.raises(AddressNackError):
        Board(gw, 0x20).servo


# --- what each call sends -------------------------------------------------------------

M32D_SERVO = [
    (lambda b: b.servo.set_width(3, 1500), "SAA130305DCP", "SWAAAAP", None),
    (lambda b: b.servo.width(3), "SAA1303SAB02P", "SWAASR05DCP", 1500),
    (lambda b: b.servo.set_angle(4, -45), "SAA130404B0P", "SWAAAAP", None),
    (lambda b: b.servo.angle(4), "SAA1304SAB02P", "SWAASR04B0P", -45.0),
    (lambda b: b.servo.pulsing(), "SAA12SAB02P", "SWASR4008P", {3, 14}),
    (lambda b: b.servo.widths(), "SAA1300SAB20P", "SWAASR" + "0000" * 15 + "09C4P", [0] * 15 + [2500]),
    (lambda b: b.servo.off(), "SAA13" + "".join("%02X0000" % c for c in range(16)) + "P",
     "SW" + "A" * 49 + "P", None),
    (lambda b: b.motor.stop(2), "SAA0F00P", "SWAAP", None),
    (lambda b: b.motor.set_all(128, -96), "SAA0E80600001P", "SWAAAAAP", None),
    (lambda b: b.motor.get(2), "SAA0ESAB04P", "SWASR80600001P", -96),
    (lambda b: b.motor.stop(), "SAA0E0000P", "SWAAAP", None),
    (lambda b: b.gpio.write("b", 0x10, 0x30), "SAA031030P", "SWAAAP", None),
    (lambda b: b.gpio.read("D"), "SAA05SAB01P", "SWASR5AP", 0x5A),
    (lambda b: b.gpio.set_modes("a", 0xF0), "SAA06F0P", "SWAAP", None),
    (lambda b: b.adc.configure([0, 1], "internal", 8), "SAA0C0203P", "SWAAAP", None),
    (lambda b: b.adc.config(), "SAA0CSAB02P", "SWASR0503P", ("avcc", 10, (0, 1))),
    (lambda b: b.spi.bind(1, "C", 2), "SAA0B010202P", "SWAAAAP", None),
    (lambda b: b.spi.configure(6, 3, True), "SAA0BFF003EP", "SWAAAAP", None),
    (lambda b: b.failsafe(), "SAA15SAB02P", "SWASR00C8P", 200),
    (lambda b: b.set_failsafe(200), "SAA1500C8P", "SWAAAP", None),
    (lambda b: b.reset_cause(), "SAA14SAB01P", "SWASR09P", frozenset({"power", "watchdog"})),
    (lambda b: b.clear_reset_cause(["watchdog"]), "SAA1408P", "SWAAP", None),
    (lambda b: b.status(), "SAA01SAB01P", "SWASR03P", Status.PIN_BUSY),
]


@pytest.mark.parametrize("call, request_, reply, result", M32D_SERVO,
                         ids=[c[1] for c in M32D_SERVO])
def test_call_sends(fake, call, request_, reply, result):
    b, line = make_board(fake, "m32d", table={request_: reply})
    assert call(b) == result
    assert line.written == [request_]


def test_motor_set_is_one_write_of_all_registers(fake):
    b, line = make_board(fake, "m32d", table={"SAA0ESAB04P": "SWASR80000000P",
                                              "SAA0E80400001P": "SWAAAAAP"})
    b.motor.set(2, -64)
    assert line.written == ["SAA0ESAB04P", "SAA0E80400001P"]


def test_slave_write_reads_status_in_the_same_request(fake):
    b, line = make_board(fake, "m128s", 0x10, {"S100B0305DCS1001S1101P": "SWAAAASWASR00P"})
    b.servo.set_width(3, 1500)
    assert line.written == ["S100B0305DCS1001S1101P"]


def test_adc_volts(fake):
    # 10 bits, AVCC: RC and RD in one request
    rd = "".join("%04X" % v for v in (1023, 512, 0, 0, 0, 0, 0, 1))
    b, line = make_board(fake, "m32d", table={"SAA0CSAB02SAA0DSAB10P": "SWASR0503SWASR%sP" % rd})
    assert b.adc.read() == [1023, 512, 0, 0, 0, 0, 0, 1]
    assert b.adc.volts()[:2] == [1023 * 5.0 / 1024, 2.5]
    assert b.adc.volts(vref=4.096)[1] == 2.048
    assert line.written == ["SAA0CSAB02SAA0DSAB10P"] * 3


def test_adc_aref_needs_vref(fake):
    rd = "FF80" + "00" * 14
    b, _ = make_board(fake, "m32d", table={"SAA0CSAB02SAA0DSAB10P": "SWASR0001SWASR%sP" % rd})
    assert b.adc.read()[:2] == [0xFF, 0x80]            # 8 bits: one byte per channel
    with pytest.raises(ValueError, match="AREF"):
        b.adc.volts()
    assert b.adc.volts(vref=2.0)[0] == 255 * 2.0 / 256


def test_spi_transfer_is_a_write_then_a_read(fake):
    b, line = make_board(fake, "m32d", table={
        "SAA0A000500P": "SWAAAAP", "SAA01SAB01P": "SWASR00P", "SAA0ASAB02P": "SWASRFF02P"})
    assert b.spi.transfer(0, b"\x05\x00") == b"\xff\x02"
    assert line.written == ["SAA0A000500P", "SAA01SAB01P", "SAA0ASAB02P", "SAA01SAB01P"]
    with pytest.raises(LimitError, match="SPI transfer of 61 bytes"):
        b.spi.transfer(0, bytes(61))


def test_servo_widths_batched_and_pipelined(fake):
    """32 channels: two SP writes of 16 triples, each with a status request
    after it, all four in flight at once (230 characters, under 256)."""
    b, line = make_board(fake, "m128s")
    first = "SAA0B" + "".join("%02X%04X" % (ch, 1000 + ch) for ch in range(16)) + "P"
    second = "SAA0B" + "".join("%02X%04X" % (ch, 1000 + ch) for ch in range(16, 32)) + "P"
    ok = "SW" + "A" * 49 + "P"
    b.gateway.serial.answer = board_answers("m128s", table={
        first: ok, second: ok, "SAA01SAB01P": "SWASR00P"})
    b.servo.set_widths({ch: 1000 + ch for ch in range(32)})
    assert line.written == [first, "SAA01SAB01P", second, "SAA01SAB01P"]
    assert line.max_in_flight == 2 * (len(first) + 1) + 2 * 12


# --- refusals -------------------------------------------------------------------------

def test_local_refusal_reads_the_status(fake):
    b, line = make_board(fake, "m32d", table={"SAA0E40000000P": "ERROR 07",
                                              "SAA01SAB01P": "SWASR03P"})
    with pytest.raises(PinBusyError) as e:
        b.motor.set_all(64, 0)
    assert str(e.value) == ("0xAA motor PWM1: write refused: PIN_BUSY "
                            "(a pin the operation needs belongs to another function)")
    assert e.value.status is Status.PIN_BUSY and e.value.addr == 0xAA
    assert e.value.register == "motor PWM1" and e.value.code == 0x07
    assert isinstance(e.value.__cause__, DataNackError)
    # after the ERROR line the V marker checks the line is in step
    assert line.written == ["SAA0E40000000P", "V", "SAA01SAB01P"]


def test_slave_refusal_found_at_frame_end(fake):
    b, line = make_board(fake, "m32d", 0x12, {"S12154E20S1201S1301P": "SWAAASWASR02P"})
    with pytest.raises(BadValueError) as e:
        b.write("sys", "FAILSAFE", [0x4E, 0x20])
    assert str(e.value).startswith("0x12 sys FAILSAFE: write refused: BAD_VALUE (")
    assert e.value.__cause__ is None and e.value.code is None
    assert line.written == ["S12154E20S1201S1301P"]


def test_slave_refusal_on_the_next_byte(fake):
    b, line = make_board(fake, "m128s", 0x10, {"S100B2805DCS1001S1101P": "ERROR 07",
                                               "S1001S1101P": "SWASR02P"})
    with pytest.raises(BadValueError) as e:
        b.write("servo", "SP", [40, 0x05, 0xDC])
    assert isinstance(e.value.__cause__, DataNackError)
    assert line.written == ["S100B2805DCS1001S1101P", "V", "S1001S1101P"]


def test_host_side_checks_send_nothing(fake):
    b, line = make_board(fake, "m32d")
    for bad in (lambda: b.servo.set_width(16, 1500), lambda: b.servo.set_width(0, -1),
                lambda: b.servo.set_angle(0, 80), lambda: b.motor.set(3, 0),
                lambda: b.motor.set(1, 256), lambda: b.adc.configure(bits=12),
                lambda: b.adc.configure(reference="vcc"), lambda: b.gpio.read("E"),
                lambda: b.gpio.write("A", 256), lambda: b.spi.transfer(0, b""),
                lambda: b.spi.bind(4, "A", 0), lambda: b.set_failsafe(18001)):
        with pytest.raises(ValueError):
            bad()
    assert line.written == []


def test_status_and_error_classes():
    codes = {s.name: int(s) for s in Status}
    assert codes == {"OK": 0, "BAD_LENGTH": 1, "BAD_VALUE": 2, "PIN_BUSY": 3,
                     "NOT_WRITABLE": 4, "NOT_READABLE": 5, "READ_WRAPPED": 6,
                     "NOT_BOUND": 7, "NO_REGISTER": 8, "DROPPED": 9}
    assert Status.BAD_VALUE.text.startswith("a value out of range")
    refusing = set(Status) - {Status.OK, Status.READ_WRAPPED}
    assert set(errors.REGISTER_ERRORS) == refusing
    for status, cls in errors.REGISTER_ERRORS.items():
        assert issubclass(cls, RegisterError) and issubclass(cls, OrfaError)
        assert type(errors.register_error(status, 0x10, "servo SP", "write")) is cls
    assert type(errors.register_error(0x42, 0x10, "servo SP", "write")) is RegisterError


# --- servo range ----------------------------------------------------------------------

def test_servo_range_the_manuals_formula():
    r = ServoRange()
    assert r.degrees(1200) == -45.0 and r.width(-45) == 1200
    assert r.width(0) == 1500 and r.width(75) == 2000 and r.width(-75) == 1000
    assert r.width(10.01) == 1567                       # 1566.73 rounded
    with pytest.raises(ValueError):
        r.width(75.5)
    flipped = ServoRange(600, 2400, 90.0, -90.0)
    assert flipped.width(90) == 600 and flipped.degrees(2400) == -90.0
    with pytest.raises(ValueError):
        ServoRange(1000, 1000)


# --- Gateway.run: pipelining, flow, noise, timeouts ----------------------------------------

def numbered(i):
    """A request with its own reply: a write of i's bytes."""
    return "SA0%04X" % i, "SWAAAP"


def echo_answers(line):
    if line == "V":
        return "V1.1"
    if line.startswith("SA0") and line.endswith("P"):
        return "SW" + "A" * ((len(line) - 4) // 2) + "P"
    if line.startswith("SA1"):
        return "SR" + line[3:5] * int(line[3:5], 16) + "P"
    return "ERROR 02"


def reads(n):
    """n reads whose replies tell them apart: SA1<k>P answers k bytes of k."""
    lines = ["SA1%02XP" % (1 + i % 40) for i in range(n)]
    return lines, ["SR" + ("%02X" % (1 + i % 40)) * (1 + i % 40) + "P" for i in range(n)]


@pytest.mark.parametrize("call", ["run", "pipeline"])
def test_run_300_in_order_within_the_flow_rule(fake, call):
    """300 reads are 2,400 characters of requests; Gateway.pipeline once
    wrote them all at once, far past the firmware's 256."""
    gw, line = fake(echo_answers)
    lines, want = reads(300)
    assert getattr(gw, call)(lines) == want
    assert line.written == lines                        # no marker: nothing went wrong
    assert 200 < line.max_in_flight < 256


def test_run_gives_error_replies_as_text(fake):
    gw, line = fake(echo_answers)
    assert gw.run(["SA102P", "Q", "SA101P"]) == ["SR0202P", "ERROR 02", "SR01P"]
    assert line.written == ["SA102P", "Q", "SA101P", "V"]


def test_run_refuses_lines_without_reply(fake):
    gw, _ = fake(echo_answers)
    for bad in ("", "   ", "# note"):
        with pytest.raises(ValueError, match="no reply"):
            gw.run(["V", bad])


def test_noise_line_is_skipped_after_a_marker(fake):
    gw, line = fake(echo_answers)
    lines, want = reads(50)
    line.extra[20] = [b"\x00\xff garbage\r\n"]
    assert gw.run(lines) == want
    assert "V" in line.written and gw.resyncs == 1
    assert gw.run(lines[:3]) == want[:3]


def test_garbled_reply_is_lost_not_misplaced(fake):
    gw, line = fake(echo_answers)
    lines, want = reads(30)
    line.garble[10] = b"SR0G0P\r\n"
    with pytest.raises(ProtocolError, match="lost to noise"):
        gw.run(lines)
    line.garble = {line._answered + 10: b"SR0G0P\r\n"}     # the 11th of the next 30
    results = gw.transactions([[p_read(1 + i % 40)] for i in range(30)])
    assert [i for i, r in enumerate(results) if isinstance(r, ProtocolError)] == [10]
    assert [r[0].data for r in results[11:]] == [bytes([1 + i]) * (1 + i) for i in range(11, 30)]


def p_read(n):
    from orfa import Read
    return Read(0xA0, n)


def test_extra_error_line_puts_the_run_out_of_step(fake):
    """An extra `ERROR 02` (a garbled request the board refused) looks like
    a reply; the displaced replies are noise, and the request that took the
    ERROR is not trusted."""
    gw, line = fake(echo_answers)
    lines, want = reads(10)
    line.extra[4] = [b"ERROR 02\r\n"]
    from orfa import Read
    results = gw.transactions([[Read(0xA0, 1 + i)] for i in range(10)])
    assert [r[0].data for r in results[:4]] == [bytes([1 + i]) * (1 + i) for i in range(4)]
    # request 4 got the extra line, its own reply came as noise after it:
    # 4 is unknown, the marker puts 5.. back in step
    assert isinstance(results[4], ProtocolError)
    assert [r[0].data for r in results[5:]] == [bytes([1 + i]) * (1 + i) for i in range(5, 10)]
    assert gw.run(lines) == want


def test_stale_line_before_a_run_is_dropped(fake):
    gw, line = fake(echo_answers)
    line._out += b"SWAAP\r\n"                       # a reply nobody waited for
    assert gw.run(["SA103P"]) == ["SR030303P"]
    assert line.written == ["V", "SA103P"]


def test_timeout_then_resync(fake):
    silent = {"SA105P"}
    gw, line = fake(lambda l: None if l in silent else echo_answers(l))
    with pytest.raises(ReplyTimeout):
        gw.run(["SA101P", "SA105P"])
    silent.clear()
    assert gw.run(["SA102P"]) == ["SR0202P"]
    assert line.written[-2:] == ["V", "SA102P"]


# --- submit: pipelining across calls ------------------------------------------------------

def test_submitted_batches_share_the_window_and_keep_their_order(fake):
    """Three batches submitted before any is waited for: one stream within
    the flow rule, each batch its own replies, whichever is waited for first."""
    gw, line = fake(echo_answers)
    lines, want = reads(90)
    batches = [gw.submit(lines[i:i + 30]) for i in (0, 30, 60)]
    assert 200 < line.max_in_flight < 256 and len(line.written) < 90
    assert batches[2].wait() == want[60:]                 # the earlier ones are read on the way
    assert batches[0].done and batches[1].done
    assert batches[0].wait() + batches[1].wait() == want[:60]
    assert line.written == lines


def test_submit_sends_at_once_and_a_request_waits_for_the_stream(fake):
    gw, line = fake(echo_answers)
    first = gw.submit(["SA101P", "SA102P"])
    assert line.written == ["SA101P", "SA102P"] and not first.done
    assert gw.request("SA103P") == "SR030303P"            # after the two submitted
    assert first.done and first.wait() == ["SR01P", "SR0202P"]


def test_submitted_transactions_and_board_ops(fake):
    b, line = make_board(fake, table={"SAA0DSAB02P": "SWASR0123P", "SA102P": "SR0202P"})
    ops = b.submit([[b.op_read("adc", "RD", 2)]])
    tx = b.gateway.submit_transactions([[p_read(2)]])
    assert line.written == ["SAA0DSAB02P", "SA102P"]
    assert tx.wait()[0][0].data == b"\x02\x02" and ops.done
    assert ops.wait() == [[b"\x01\x23"]]


def test_an_error_reply_is_confirmed_after_the_later_batches(fake):
    """An ERROR reply in one batch: its wait reads the later batches too,
    then a marker checks the line was in step."""
    gw, line = fake(echo_answers)
    first = gw.submit(["SA101P", "Q"])
    second = gw.submit(["SA102P"])
    assert first.wait() == ["SR01P", "ERROR 02"]
    assert second.done and second.wait() == ["SR0202P"]
    assert line.written == ["SA101P", "Q", "SA102P", "V"]


# --- the serial port ----------------------------------------------------------------------

def test_bad_port_is_one_line():
    with pytest.raises(SerialError) as e:
        Gateway("/dev/ttyORFA-none")
    assert str(e.value) == "cannot open /dev/ttyORFA-none: [Errno 2] No such file or directory"
    with pytest.raises(SerialError, match="^cannot open nope://x: "):
        Board.open("nope://x")


@pytest.mark.parametrize("rate", [0, -1, "abc", None, 2 ** 40])
def test_a_bad_baudrate_is_a_value_error_as_pyserials(rate):
    """Gateway(port, baudrate=...) keeps pyserial's convention: a rate that
    is none is the caller's ValueError (serial.Serial's words), raised
    before any port is opened, not an OrfaError of the port; so are
    Board.open's, SMBus's and busio.I2C's, which pass it on."""
    from orfa.busio import I2C
    from orfa.smbus import SMBus
    for opener in (lambda: Gateway("loop://", baudrate=rate),
                   lambda: Board.open("/dev/ttyORFA-none", baudrate=rate),
                   lambda: SMBus("/dev/ttyORFA-none", baudrate=rate),
                   lambda: I2C("/dev/ttyORFA-none", baudrate=rate)):
        with pytest.raises(ValueError) as e:
            opener()
        assert not isinstance(e.value, errors.OrfaError)
        assert str(e.value) == "Not a valid baudrate: %r" % (rate,)


@pytest.mark.parametrize("timeout", [-1, "abc", None, float("nan"), float("inf")])
def test_a_bad_timeout_is_a_value_error_too(timeout):
    """A timeout that is no number of seconds is a ValueError as pyserial
    has it ('Not a valid timeout'), raised before the port is opened: it
    was a SerialError, or for None a TypeError at the first request."""
    with pytest.raises(ValueError) as e:
        Gateway("loop://", timeout=timeout)
    assert not isinstance(e.value, errors.OrfaError)
    assert str(e.value) == "Not a valid timeout: %r (seconds, 0 or more)" % (timeout,)


def test_a_silent_opening_names_the_rate():
    """No board answers the opening sync (a port nobody answers; a board
    built for another rate gets only garbage): the error says at which rate
    it asked, and that a gateway answers only at its build's."""
    import os
    import pty
    master, slave = pty.openpty()
    try:
        with Gateway(os.ttyname(slave), baudrate=460800, timeout=0.2) as gw:
            with pytest.raises(ReplyTimeout) as e:
                gw.request("V")
    finally:
        os.close(master)
        os.close(slave)
    assert str(e.value) == ("no reply line (got b''); nothing answered the opening sync at 460800"
                            " baud (a gateway answers only at the rate it was built for, its BAUD)")


@pytest.mark.parametrize("rate", [230400, 460800, 921600, 12345, "460800"])
def test_a_rate_pyserial_takes_opens(rate):
    """Rates pyserial sets are taken as it takes them (a number in a string
    too): the line, not the library, tells whether a board answers there."""
    with Gateway("loop://", baudrate=rate, sync=False) as gw:
        assert gw.serial.baudrate == int(rate)


def test_extra_error_line_among_equal_replies(fake):
    """Replies of one shape cannot show where an extra line came in: the
    marker after the run finds one line too many, and every result from
    the first ERROR line on is unknown."""
    gw, line = fake(echo_answers)
    line.extra[3] = [b"ERROR 04\r\n"]
    from orfa import Read
    results = gw.transactions([[Read(0xA0, 1)] for i in range(8)])
    assert [r[0].data for r in results[:3]] == [b"\x01"] * 3
    assert all(isinstance(r, ProtocolError) and "out of step" in str(r) for r in results[3:])
    assert line.written[-1] == "V"
    assert gw.run(["SA101P"]) == ["SR01P"]


# --- which lines can answer a request (orfa.flow) --------------------------------------


@pytest.mark.parametrize("request_, good, bad", [
    ("V", ["V1.1", "ERROR 02"], ["V", "SWP", "ERROR 2"]),
    ("x", ["X"], ["XX", "V1.1"]),
    ("L", ["LAA"], ["L", "LAAA"]),
    ("L 20", ["L20", "ERROR 04"], ["C0064"]),
    ("C0064", ["C0063"], ["C63"]),
    ("S AA 13 03 05 dc P", ["SWAAAAP", "ERROR 07"], ["SWAAAP", "SWAAAAAP"]),
    ("S A0 10 S A1 02 P", ["SWASR4142P", "ERROR 06"], ["SWASR41P", "SRP"]),
    ("S A0 10", ["ERROR 05"], ["SWAP"]),            # no P: only an error can answer
    ("S AA 1", ["ERROR 03"], ["SWAP"]),
    ("Q", ["ERROR 02"], ["Q"]),
])
def test_reply_patterns(request_, good, bad):
    pattern = flow.reply_pattern(request_)
    assert all(flow.plausible(pattern, r) for r in good), request_
    assert not any(flow.plausible(pattern, r) for r in bad), request_


def test_lines_without_reply_have_no_pattern():
    assert flow.reply_pattern("") is None
    assert flow.reply_pattern("    ") is None
    assert flow.reply_pattern("# SAA00P") is None
    assert flow.request_cost("SAA00P") == 7


def test_introspection_after_a_stale_line(fake):
    gw, line = fake(board_answers("m32d"))
    line._out += b"ERROR 02\r\n"                    # left over from before
    b = Board(gw)
    assert b.map.board == "m32d"
    assert line.written[0] == "V" and gw.resyncs == 1


def test_the_duty_range_is_checked_in_one_place(fake, monkeypatch):
    """Motor, `orfa motor` and the dashboard all ask clients.motor.is_duty:
    a narrower MAX_DUTY narrows all three, and nothing reaches the line."""
    from orfa.cli import devices
    from orfa.clients import motor
    from orfa.dash import live
    b, line = make_board(fake)
    for duty in (255, -255):
        assert motor.is_duty(duty)
    for duty in (256, -256, 1.0, True, None):
        assert not motor.is_duty(duty)
    monkeypatch.setattr(motor, "MAX_DUTY", 100)
    with pytest.raises(ValueError, match="duty must be"):
        b.motor.set_all(101, 0)
    with pytest.raises(errors.UsageError, match="duty '101'"):
        devices._duty("101")
    with pytest.raises(errors.ControlError, match="motor: duty -101 is outside"):
        live.set_motor(b, {}, {"motor": 1, "duty": -101})
    assert line.written == []
