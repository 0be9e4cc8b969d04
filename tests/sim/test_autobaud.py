"""BAUD=auto firmware (docs/protocol.md, "Autobaud"): after reset it finds
the PC's rate from the eight 0x0D of the preamble, at every one of the ten
rates on both boards, also after noise, and then talks normally.

The autobaud builds go to build/<board>-gate-auto/ (the default
fixed-rate build stays); the simulator's serial line decodes at each end's
own rate, so a wrong rate gets no reply (test_serial_line.py).
"""

import random

import pytest
import serial

from conftest import REPLY_TIMEOUT, board_sent, build_gateway, require_builds, wait_quiet
from orfa.protocol import AUTOBAUD_PREAMBLE, AUTOBAUD_RATES, F_CPU
from orfa.sim import BOARDS, REPO_ROOT, SimBoard
from orfa.simctl import RX_MAX, SimControlError

EEPROM = 0xA0
COUNT = {"m32d": "SWAASR07P", "m128s": "SWAASR06P"}
#: Driver 2, the GPIO: UID, version 1.1, its registers
GPIO_INFO = {"m32d": "SWAASR002001010208P", "m128s": "SWAASR002101010204P"}


def start(board):
    require_builds([board])
    return SimBoard(board, trace=True, control=True, eeproms=[EEPROM],
                    firmware=build_gateway(board, "auto"))


def talks(sim, gw, board, rate):
    """The gateway answers local and bus requests at `rate`."""
    assert gw.request("V") == "V1.1"
    assert gw.request("S AA 00 00 S AB 01 P") == COUNT[board]
    assert gw.request("S AA 00 02 S AB 06 P") == GPIO_INFO[board]
    assert gw.request("S A0 10 48 69 P") == "SWAAAP"
    assert gw.request("S A0 10 S A1 02 P") == "SWASR4869P"
    line = sim.control.line()
    assert line["board"] == line["bit"] == F_CPU // rate


@pytest.mark.parametrize("rate", AUTOBAUD_RATES)
@pytest.mark.parametrize("board", BOARDS)
def test_every_rate_is_found(board, rate):
    with start(board) as sim:
        # a board that has not heard a preamble yet does not listen at all
        assert sim.control.line()["rxen"] == 0
        with sim.gateway(rate, autobaud=True, timeout=REPLY_TIMEOUT) as gw:
            talks(sim, gw, board, rate)


def noise(rng, n, avoid=b"\r"):
    return bytes(b for b in (rng.randrange(256) for _ in range(4 * n)) if b not in avoid)[:n]


@pytest.mark.parametrize("board,noise_rate,rate", [
    ("m32d", 9600, 115200), ("m32d", 115200, 2400), ("m32d", 2400, 38400),
    ("m128s", 57600, 14400), ("m128s", 4800, 76800), ("m128s", 115200, 9600),
    ("m32d", 460800, 230400), ("m32d", 230400, 460800), ("m32d", 2400, 460800),
    ("m128s", 460800, 230400), ("m128s", 230400, 460800), ("m128s", 460800, 2400),
])
def test_noise_first_then_the_preamble(board, noise_rate, rate):
    """Random bytes at another rate, then bytes at the right rate that are
    not 0x0D, then the preamble: the board ends talking at the right rate."""
    rng = random.Random("%s %d %d" % (board, noise_rate, rate))
    with start(board) as sim, sim.gateway(noise_rate, timeout=REPLY_TIMEOUT) as gw:
        sim.pc_write(gw.serial, noise(rng, 40))
        sim.wait_s(45 * 10 / noise_rate)
        gw.serial.baudrate = rate
        sim.pc_write(gw.serial, b"hello V S AA P \n" + noise(rng, 20))
        sim.wait_s(40 * 10 / rate)
        sim.preamble(gw.serial)
        talks(sim, gw, board, rate)


def in_the_known_limit(wrong, rate):
    """docs/protocol.md, Autobaud, Noise: a fresh rate of 115200 or more
    followed by the real preamble at another rate of 57600 or more is not
    always moved (the fresh rate's receive interrupts bend the preamble's
    runs while they are timed; at half the fresh rate it decodes without
    framing errors): the host, getting no reply, sends its preamble again."""
    return wrong >= 115200 and rate >= 57600


@pytest.mark.parametrize("board,wrong,rate", [
    ("m32d", 9600, 115200), ("m128s", 115200, 9600), ("m32d", 2400, 57600),
    ("m32d", 460800, 2400), ("m128s", 460800, 2400), ("m32d", 2400, 460800),
    ("m128s", 230400, 460800),
])
def test_a_preamble_at_a_wrong_rate_first_is_not_kept(board, wrong, rate):
    """0x0Ds at another rate, then quiet, look like a preamble and lock that
    rate; the real preamble after them moves it (no request was accepted).
    In the known limit (in_the_known_limit) the host sends its preamble and
    a V again while V gets no reply, as docs/protocol.md tells it: a second
    preamble always moves it (the first V's framing errors send a fresh
    rate back to detection); outside it one preamble does."""
    with start(board) as sim, sim.gateway(wrong, timeout=REPLY_TIMEOUT) as gw:
        sim.preamble(gw.serial)
        assert sim.control.line()["board"] == F_CPU // wrong
        gw.serial.baudrate = rate
        sim.preamble(gw.serial)
        if in_the_known_limit(wrong, rate) and sim.control.line()["board"] != F_CPU // rate:
            # a V at the wrong rate for the board: no reply within 10 ms
            # of simulated time (a reply at either rate is out in 0.1 ms)
            since = sim.pc_write(gw.serial, b"V\n")
            sim.control.wait(F_CPU // 100)
            assert board_sent(sim, since) == b""
            gw.reset_input_buffer()
            sim.preamble(gw.serial)
        talks(sim, gw, board, rate)


@pytest.mark.parametrize("board", BOARDS)
def test_a_slower_pc_later_brings_the_board_back_to_detection(board):
    """After talking at 115200, a PC at 2400 sends framing errors (a run of
    them ends a proven rate); its preamble is then found."""
    with start(board) as sim, sim.gateway(115200, autobaud=True, timeout=REPLY_TIMEOUT) as gw:
        assert gw.request("V") == "V1.1"
        gw.serial.baudrate = 2400
        sim.preamble(gw.serial)
        sim.preamble(gw.serial)
        talks(sim, gw, board, 2400)


@pytest.mark.parametrize("board", BOARDS)
def test_the_preamble_gets_no_reply(board):
    """The eight CRs are empty lines: nothing comes back, before or after
    the rate is found."""
    with start(board) as sim, sim.gateway(19200, autobaud=True, timeout=REPLY_TIMEOUT) as gw:
        t0 = sim.control.time()
        sim.pc_write(gw.serial, AUTOBAUD_PREAMBLE)
        sim.control.wait(F_CPU // 10)
        assert board_sent(sim, t0) == b""
        assert gw.request("V") == "V1.1"


@pytest.mark.parametrize("board", BOARDS)
def test_fixed_rate_build_does_not_answer_a_pc_at_9600(board):
    """The default build is 115200: a PC at 9600 gets no valid reply."""
    require_builds([board])
    with SimBoard(board, trace=True, control=True) as sim, \
            sim.gateway(9600, autobaud=True, timeout=REPLY_TIMEOUT) as gw:
        t0 = sim.control.time()
        sim.pc_write(gw.serial, b"V\r")
        sim.control.wait(F_CPU // 10)
        assert b"V1.1" not in board_sent(sim, t0)
        # its receiver got frames from the PC's bits, never a 'V'
        rx = [e for e in sim.trace_events(kinds=["uart rx"]) if e.cycle >= t0]
        assert rx and not any(e.fields[0] == "56" for e in rx), rx


@pytest.mark.parametrize("board", BOARDS)
def test_receive_overflow_is_error_04(board):
    """The receive ring's overflow at a found rate (serialgate/sg_rx.c's
    lost-run record, out of line with autobaud): a request that lost
    characters is ERROR 04, every other reply exact, one reply a request;
    the record of a run that lost only empty lines' ends adds none."""
    with start(board) as sim, sim.gateway(115200, autobaud=True, timeout=REPLY_TIMEOUT) as gw:
        request = "S AA 00 01 S AB 3C P"         # 20 characters, 127 back
        want = gw.request(request)
        port = gw.serial
        port.write((request + "\n").encode() * 100)
        lines = [port.readline().rstrip(b"\r\n").decode() for _ in range(100)]
        assert [line for line in lines if line not in (want, "ERROR 04")] == []
        assert "ERROR 04" in lines and want in lines
        port.write((request + "\r").encode() * 4 + b"\n" * 330 + b"V\r")
        lines = [port.readline().rstrip(b"\r\n").decode() for _ in range(5)]
        assert lines[:4] == [want] * 4 and lines[4] in ("V1.1", "ERROR 04")
        assert gw.request("L") == "LAA"


@pytest.mark.parametrize("board", BOARDS)
def test_a_flood_before_the_first_reply_ends_in_no_reset(board):
    """A host that floods the line right after its preamble (V lines back to
    back at 460800 for 0.6 s, beyond the flow rule), before any reply:
    while the rate is fresh the idle main loop records the line's runs (a
    preamble at another rate would move it) until the line is quiet, and
    the flood never let it be: 256 ms without the watchdog fed, a reset,
    and again every 256 ms, the board never talking. Each ring's worth of
    runs now feeds it (firmware/autobaud.c, ab_scan()): no reset, and after
    the flood (its lost requests answered `ERROR 04`) the board answers."""
    rate = 460800
    per_char = 10 * F_CPU // rate
    blob = b"V\n" * (RX_MAX // 2)
    with start(board) as sim, serial.Serial(sim.port, rate, timeout=REPLY_TIMEOUT) as port:
        ctl = sim.control
        ctl.wait(1000)                      # the simulator reads the port's rate
        # the preamble, then 20 ms of quiet (as a host waits), then the
        # flood: one batch, so its spacing is the simulator's, however late
        # a loaded machine hands the requests over (two requests let the
        # simulator run past the flood's cycle in between)
        quiet = 1000 + len(AUTOBAUD_PREAMBLE) * per_char + F_CPU // 50
        replies = ctl.requests(["rx +1000 %s" % AUTOBAUD_PREAMBLE.hex().upper(),
                                "wait %d" % quiet, "rx +1 %s" % blob.hex().upper()])
        at = first = int(replies[2])
        while at < first + F_CPU * 3 // 5:
            try:
                at = ctl.rx(at, blob)
            except SimControlError as e:
                if "is past" in str(e):     # the host fell behind: on from now
                    at = ctl.rx_after(1000, blob)
                else:                       # the simulator's queue is full
                    assert "too many" in str(e), e
                    ctl.wait(8 * RX_MAX * per_char)
        ctl.wait(at - ctl.time() + F_CPU // 50)
        wait_quiet(ctl, port, F_CPU // 50)
        assert sim.trace_events(kinds=["reset"]) == []
        port.write(b"V\n")
        assert port.readline() == b"V1.1\r\n"


CHECK_ELF = REPO_ROOT / "build" / "sim-fw" / "autobaud_check.elf"
PORTA, PORTB, PORTC = 0x3B, 0x38, 0x35   # data addresses on the ATmega32


def test_the_pair_analysis_keeps_its_rule():
    """firmware/autobaud.c's pair analysis, in assembly, gives the rate its
    rule in plain C gives (tests/sim/fw/autobaud_check.c) on 4096 records:
    random ones, and 0x0D pairs bent by up to half a bit a run or 20 % a
    frame, across every bound of the rule."""
    if not CHECK_ELF.is_file():
        pytest.fail("missing %s: run `make sim`" % CHECK_ELF, pytrace=False)
    with SimBoard("m32d", control=True, firmware=CHECK_ELF) as sim:
        ctl = sim.control
        while ctl.peek(PORTC)[0] != 0xA5:
            assert ctl.time() < 40 * F_CPU, "the check did not finish"
            ctl.wait(F_CPU // 2)
        wrong, accepted = ctl.peek(PORTA)[0], ctl.peek(PORTB)[0] * 64
    assert wrong == 0, "%d records where the analysis and its rule differ" % wrong
    # the rule's every branch taken: many records found a rate, most did not
    assert 256 <= accepted <= 2048, accepted
