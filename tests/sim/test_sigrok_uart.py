"""The simulator's VCD as a logic analyzer's capture (docs/simulator.md,
"VCD"): Debian's sigrok-cli, with sigrok's own `uart` decoder on the
gateway's RXD and TXD wires, decodes exactly the bytes the host sent and
received, each frame starting at the cycle the trace gives; and it reads a
capture of one simulated second in under 10 s."""

import shutil

import pytest
import serial

from conftest import REPLY_TIMEOUT, board_sent, require_builds
from orfa.protocol import F_CPU
from orfa.sim import BOARDS, SimBoard
from sigrok import TIMESCALE, decode as sigrok_decode, needs_sigrok, sample_cycle

#: The gateway's serial pins, as the VCD names its wires (the board files'
#: UART_RX and UART_TX: USART1's RXD1/TXD1 on the M128-S).
WIRES = {"m32d": ("D0", "D1"), "m128s": ("D2", "D3")}
BIT = F_CPU // 115200                          # 64 cycles a bit on both sides
REQUESTS = ["V", "S A0 10 48 69 P", "S A0 10 S A1 02 P", "S AA 00 00 S AB 01 P", "V"]

pytestmark = needs_sigrok


def decode(path, board):
    """sigrok-cli's uart decoder on the board's RXD (rx) and TXD (tx) wires:
    {"RX": [(start cycle, byte)], "TX": [...]}, and the seconds it took."""
    rx, tx = WIRES[board]
    rows, took = sigrok_decode(path, "uart:rx=%s:tx=%s:baudrate=115200" % (rx, tx),
                               "uart=rx-data:tx-data")
    return {k: [(begin, int(text, 16)) for begin, _, text in rows.get(k, [])]
            for k in ("RX", "TX")}, took


def run_gateway(board, seconds=1.0):
    """A gateway with an EEPROM at A0 and --vcd; the host writes REQUESTS
    on its serial port and reads each reply line; the simulator runs on to
    `seconds` of simulated time and exits (the VCD is complete then).
    Returns the sim, the bytes sent and received, and the capture's path."""
    require_builds([board])
    sim = SimBoard(board, eeproms=(0xA0,), control=True, vcd=True, trace=True).start()
    sent, got = b"", b""
    try:
        with serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
            for req in REQUESTS:
                line = req.encode() + b"\r"
                port.write(line)
                sent += line
                reply = port.readline()
                assert reply.endswith(b"\r\n"), (req, reply)
                got += reply
            ctl = sim.control
            ctl.wait(max(1000, int(seconds * F_CPU) - ctl.time()))
            # nothing more came: what the board sent (its trace, simulated
            # time) is what the host read, no wall-clock wait for silence
            assert board_sent(sim, 0) == got
    except BaseException:
        sim.stop()
        raise
    sim.stop(keep_dir=True)
    return sim, sent, got, sim.vcd_path


@pytest.mark.parametrize("board", BOARDS)
def test_sigrok_decodes_both_directions_byte_for_byte(board):
    """RX (the PC's bytes on RXD) and TX (the board's on TXD) as sigrok's
    uart decoder reads them: the host's requests and the replies it read,
    equal byte for byte. And in time: sigrok's data annotation starts one
    bit after the start bit's edge, give or take its sample points (a
    sample is 0.74 cycle), so each TX frame is at its `uart tx` cycle (the
    shift register taking the byte) and each RX frame 10 bits before its
    `uart rx` (the end of its stop bit; RXD's edges are stamped at the
    instruction boundary, < 5 cycles late), within 2 cycles. The timescale
    is the documented one."""
    sim, sent, got, path = run_gateway(board, seconds=0.2)
    try:
        assert "$timescale %s $end" % TIMESCALE in path.read_text()
        frames, _ = decode(path, board)
        assert bytes(b for _, b in frames["RX"]) == sent
        assert bytes(b for _, b in frames["TX"]) == got
        for kind, name, start, late in (("TX", "uart tx", 0, 0), ("RX", "uart rx", -10 * BIT, 5)):
            want = [(e.cycle + start, int(e.fields[0], 16))
                    for e in sim.trace_events(kinds=[name])]
            assert [b for _, b in frames[kind]] == [b for _, b in want]
            off = [c - BIT - w for (c, _), (w, _) in zip(frames[kind], want)]
            assert all(-2 <= d <= late + 2 for d in off), (kind, off)
    finally:
        shutil.rmtree(sim.dir, ignore_errors=True)


def test_one_simulated_second_decodes_in_under_10_s():
    """A capture of a whole simulated second (every pin of the gateway, the
    requests in it): sigrok-cli reads and decodes it in under 10 s, and
    finds the same bytes."""
    sim, sent, got, path = run_gateway("m32d", seconds=1.0)
    try:
        last = [line for line in path.read_text().splitlines() if line.startswith("#")][-1]
        assert sample_cycle(int(last[1:])) >= F_CPU  # the file spans a second
        frames, took = decode(path, "m32d")
        assert (bytes(b for _, b in frames["RX"]), bytes(b for _, b in frames["TX"])) == \
            (sent, got)
        assert took < 10, "sigrok-cli took %.1f s over one simulated second" % took
    finally:
        shutil.rmtree(sim.dir, ignore_errors=True)
