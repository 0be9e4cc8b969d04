"""The simulator's serial line (docs/simulator.md, Serial line): the PC's
rate comes from its port's termios, RXD shows the PC's bit waveform, and
each end decodes the other's bits at its own rate, so a PC at the wrong rate
gets garbage or nothing, as on a real line; equal rates behave as before.

Fixed-rate firmware at other rates is built into build/<board>-gate-<rate>/.
"""

import os
import signal

import pytest
import serial

from conftest import REPLY_TIMEOUT, board_sent, build_gateway, require_builds
from orfa.gateway import Gateway
from orfa.protocol import F_CPU
from orfa.sim import BOARDS, SimBoard
from orfa.simctl import SimControlError

RXD = {"m32d": "D0", "m128s": "D2"}
TXD = {"m32d": "D1", "m128s": "D3"}
#: A cycle a fresh simulator has not reached when the test asks.
AT = 1 << 24
#: Replies to V or a driver count take a few byte times at most.
REPLY_CYCLES = 200 * F_CPU // 2400


def sim_for(board, elf=None, **kw):
    require_builds([board])
    return SimBoard(board, trace=True, control=True, firmware=elf, **kw)


def test_pc_rate_follows_the_termios_also_bother_rates():
    """pyserial sets 14400, 28800 and 76800 through BOTHER (termios2): the
    simulator reads them as numbers, and follows every change."""
    with sim_for("m32d") as sim, serial.Serial(sim.port, 9600) as port:
        ctl = sim.control
        for rate in (9600, 14400, 28800, 76800, 115200, 2400, 57600):
            port.baudrate = rate
            ctl.wait(1000)
            line = ctl.line()
            assert (line["pc"], line["bit"]) == (rate, F_CPU // rate)
        # the board's side: UBRR 3 at 115200, 64 cycles a bit
        assert (line["ubrr"], line["board"], line["rxen"]) == (3, 64, 1)


@pytest.mark.parametrize("board", BOARDS)
def test_rxd_pin_shows_the_pc_waveform(board):
    """0x0D at 9600 from cycle AT: start 0, bits 1 0 1 1 0 0 0 0, stop 1,
    768 cycles each, on the board's RXD pin (idle high, driven from outside).
    A pin edge is stamped at the instruction boundary after it (< 5 cycles)."""
    bit = F_CPU // 9600
    with sim_for(board) as sim, serial.Serial(sim.port, 9600) as port:
        ctl = sim.control
        ctl.wait(1000)
        assert ctl.pin(RXD[board]) == (1, "in ext")
        assert ctl.rx(AT, b"\r") == AT + 10 * bit
        ctl.wait(AT + 11 * bit - ctl.time())
        edges = ctl.edges(RXD[board], AT)
        want = [(AT, 0), (AT + bit, 1), (AT + 2 * bit, 0), (AT + 3 * bit, 1),
                (AT + 5 * bit, 0), (AT + 9 * bit, 1)]
        assert [lv for _, lv in edges] == [lv for _, lv in want]
        assert all(0 <= c - w < 5 for (c, _), (w, _) in zip(edges, want)), edges
        port.close()


def frame_edges(start, byte, bit):
    """The edges of one 8N1 frame whose start bit falls at `start`."""
    levels = [0] + [(byte >> k) & 1 for k in range(8)] + [1]
    out, level = [], 1
    for k, lv in enumerate(levels):
        if lv != level:
            out.append((start + k * bit, lv))
            level = lv
    return out


@pytest.mark.parametrize("board", BOARDS)
def test_txd_pin_shows_the_board_frames(board):
    """The reply to V at 115200 on the board's TXD pin (M32-D TXD = D1,
    M128-S TXD1 = D3), owned by the transmitter and idle high: each byte's
    frame from the cycle its shift register took it (the trace's `uart tx`),
    64 cycles a bit, every edge at its exact cycle."""
    bit = F_CPU // 115200
    with sim_for(board) as sim, serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
        ctl = sim.control
        ctl.wait(1000)
        assert ctl.pin(TXD[board]) == (1, "out uart")
        assert ctl.rx(AT, b"V\r") == AT + 20 * bit
        assert port.readline() == b"V1.1\r\n"
        ctl.wait(AT + 20 * bit + REPLY_CYCLES - ctl.time())
        sent = [(e.cycle, int(e.fields[0], 16)) for e in sim.trace_events(kinds=["uart tx"])
                if e.cycle >= AT]
        assert bytes(b for _, b in sent) == b"V1.1\r\n"
        want = [e for start, byte in sent for e in frame_edges(start, byte, bit)]
        assert ctl.edges(TXD[board], AT) == want
        assert ctl.level(TXD[board]) == 1
        assert ctl.measure(TXD[board], 20, AT) == {"steady": 1}    # the line stopped


def resync(gw):
    """After garbage: `V` until its reply. The garbage's replies may still be
    on their way through the pty (the kernel hands bytes over when it gets
    to it), so the next request's reply is the first V1.1, not the next
    line."""
    gw.send(b"V\r")
    lines = []
    while "V1.1" not in lines:
        lines.append(gw.read_reply())          # ReplyTimeout if V1.1 never comes
        assert len(lines) <= 4, lines          # a garbage line gets one reply at most


def send_at_pc_rate(sim, rate, data=b"V\r", times=3):
    """`data` from a PC at `rate`, `times` times, each on the line at a fixed
    cycle (`rx +N`, at the PC's termios rate) with REPLY_CYCLES after it, all
    in simulated time; the cycle the first one was scheduled from."""
    ctl = sim.control
    ctl.wait(1000)
    assert ctl.line()["pc"] == rate            # the port's termios, seen
    start = ctl.time()
    for _ in range(times):
        end, woke = ctl.requests(["rx +1000 %s" % data.hex().upper(),
                                  "wait %d" % (1000 + len(data) * 10 * F_CPU // rate
                                               + REPLY_CYCLES)])
        assert int(woke) - int(end) >= REPLY_CYCLES
    return start


@pytest.mark.parametrize("board", BOARDS)
def test_pc_at_9600_gets_no_valid_reply_from_a_115200_build(board):
    """The board's USART samples the PC's 9600 bits at 115200: framing
    errors (the firmware reads them: FE in UCSRA) and garbage, never V1.1."""
    with sim_for(board) as sim, serial.Serial(sim.port, 9600, timeout=0):
        start = send_at_pc_rate(sim, 9600)
        assert b"V1.1" not in board_sent(sim, start)
        line = sim.control.line()
        assert line["fe"] > 0                  # frames with FE taken from UDR
        rx = [e for e in sim.trace_events(kinds=["uart rx"]) if e.cycle >= start]
        assert any(e.fields[1:] == ("fe",) for e in rx)
        assert not any(e.fields[0] == "56" for e in rx)     # never a 'V'


@pytest.mark.parametrize("board", BOARDS)
def test_pc_at_115200_gets_no_valid_reply_from_a_9600_build(board):
    elf = build_gateway(board, 9600)
    with sim_for(board, elf) as sim, serial.Serial(sim.port, 115200, timeout=0):
        start = send_at_pc_rate(sim, 115200)
        assert b"V1.1" not in board_sent(sim, start)
        rx = [e for e in sim.trace_events(kinds=["uart rx"]) if e.cycle >= start]
        assert rx and not any(e.fields[0] == "56" for e in rx), rx


@pytest.mark.parametrize("rate", [2400, 9600, 57600])
@pytest.mark.parametrize("board", BOARDS)
def test_matched_rates_work(board, rate):
    elf = build_gateway(board, rate)
    with sim_for(board, elf, eeproms=[0xA0]) as sim, \
            Gateway(sim.port, baudrate=rate, timeout=REPLY_TIMEOUT) as gw:
        assert gw.request("V") == "V1.1"
        assert gw.request("S AA 00 00 S AB 01 P") == \
            {"m32d": "SWAASR07P", "m128s": "SWAASR06P"}[board]
        assert gw.request("S A0 10 48 69 P") == "SWAAAP"
        assert gw.request("S A0 10 S A1 02 P") == "SWASR4869P"
        line = sim.control.line()
        assert line["board"] == line["bit"] == F_CPU // rate
        assert line["fe"] == 0


def test_rx_requests_go_at_the_pc_rate():
    """Scheduled bytes are the PC's: 10 bit times of its rate each."""
    elf = build_gateway("m32d", 9600)
    with sim_for("m32d", elf) as sim, serial.Serial(sim.port, 9600, timeout=REPLY_TIMEOUT) as port:
        ctl = sim.control
        ctl.wait(1000)
        assert ctl.rx(AT, b"V\r") == AT + 2 * 10 * 768
        assert port.readline() == b"V1.1\r\n"
        rx = sim.trace_events(kinds=["uart rx"])
        assert [(e.cycle, e.fields[0]) for e in rx] == [(AT + 7680, "56"), (AT + 15360, "0D")]


def test_rx_goes_at_the_rate_set_just_before_it():
    """A program that sets its port's rate and at once asks for `rx` (a
    test opening its port at 460800, then flooding) gets its bytes at that
    rate. The simulator read the rate once a turn of its loop, before it
    ran a batch of cycles and answered the requests that came meanwhile:
    a rate set during the batch reached `rx` a turn late, and its bytes
    went at the old rate (CI: 179 requests of a flood lost to framing
    errors, most runs under load). Here the simulator, running free, is
    stopped (mostly inside a batch), the rate set and the request sent,
    then let go on: each time the board gets a V at 460800 and answers."""
    rate = 460800
    byte = 10 * F_CPU // rate
    with sim_for("m32d", build_gateway("m32d", rate), extra_args=["--no-idle-throttle"]) as sim, \
            serial.Serial(sim.port, 9600, timeout=REPLY_TIMEOUT) as port:
        ctl = sim.control
        for _ in range(6):
            port.baudrate = 9600
            ctl.wait(1000)                          # the PC is at 9600 now
            assert ctl.line()["pc"] == 9600
            before = ctl.time()
            os.kill(sim.proc.pid, signal.SIGSTOP)
            try:
                port.baudrate = rate
                ctl.sock.sendall(b"rx +1000 560D\n")
            finally:
                os.kill(sim.proc.pid, signal.SIGCONT)
            reply = b""
            while not reply.endswith(b"\n"):
                reply += ctl.sock.recv(4096)
            end = int(reply)
            ctl.wait(end - ctl.time() + REPLY_CYCLES)
            rx = [e for e in sim.trace_events(kinds=["uart rx"]) if e.cycle > before]
            assert [(e.cycle, e.fields[0]) for e in rx] == [(end - byte, "56"), (end, "0D")]
            assert board_sent(sim, end) == b"V1.1\r\n"
            port.read(port.in_waiting)


def test_pc_changing_its_rate_mid_session_is_followed():
    """The PC's bytes are read at the rate its port had when the simulator
    took them: each write is waited for in simulated time (SimBoard.pc_write)
    before the rate changes."""
    with sim_for("m32d") as sim, Gateway(sim.port, timeout=REPLY_TIMEOUT) as gw:
        ctl = sim.control
        port = gw.serial
        assert gw.request("V") == "V1.1"
        port.baudrate = 9600
        t0 = ctl.time()
        sim.pc_write(port, b"V\r")
        ctl.wait(REPLY_CYCLES)
        assert b"V1.1" not in board_sent(sim, t0)
        assert ctl.line()["pc"] == 9600
        port.baudrate = 115200
        # end the garbage line (whatever it answers), then talk again
        sim.pc_write(port, b"\r")
        ctl.wait(REPLY_CYCLES)
        assert ctl.line()["pc"] == 115200
        resync(gw)
        assert gw.request("S AA 00 00 S AB 01 P") == "SWAASR07P"


def test_a_pc_that_moves_to_the_board_rate_is_heard():
    elf = build_gateway("m128s", 19200)
    with sim_for("m128s", elf) as sim, Gateway(sim.port, timeout=REPLY_TIMEOUT) as gw:
        ctl = sim.control
        port = gw.serial
        t0 = ctl.time()
        sim.pc_write(port, b"V\r")
        ctl.wait(REPLY_CYCLES)
        assert b"V1.1" not in board_sent(sim, t0)
        port.baudrate = 19200
        sim.pc_write(port, b"\r")
        ctl.wait(REPLY_CYCLES)
        resync(gw)
        assert gw.request("V") == "V1.1"


def test_line_counts_the_bytes_taken_from_the_port():
    """`line`'s pty: every byte the simulator took from the PC's port, so a
    test waits for its write in simulated time; a byte never written is
    never counted (SimControlError after the timeout, one line)."""
    with sim_for("m32d") as sim, serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
        ctl = sim.control
        before = ctl.line()["pty"]
        sim.pc_write(port, b"V\r")
        assert ctl.line()["pty"] == before + 2
        assert port.readline() == b"V1.1\r\n"
        with pytest.raises(SimControlError, match="took %d of %d bytes" % (before + 2, before + 3)):
            ctl.wait_taken(before + 3, timeout=0.3)
