"""The simulator's scheduled serial input: the control request `rx CYCLE HEX...`
(docs/simulator.md, Serial line and Control interface).

Every test starts fresh simulators (no module scope): what is measured here is
the board's state at a given cycle after power-up, which only a fresh board has.
"""

import re
import threading
import time

import pytest
import serial

from conftest import F_CPU, REPLY_TIMEOUT, board_sent, require_builds
from orfa.sim import BOARDS, SimBoard
from orfa.simctl import RX_MAX, SimControlError

#: A cycle a fresh simulator has not reached when the test asks (about 2.3 s
#: simulated after power-up; the test asks about 0.1 s in).
AT = 1 << 24
#: Far enough ahead that nothing scheduled there is reached during a test.
FAR = 1 << 32
BYTE = 640                                 # cycles per byte at 115200 baud, 8N1
REQUEST = b"S AA 00 00 S AB 01 P\r"        # the driver count, through introspection
USAGE = "ERR rx CYCLE HEX...: CYCLE decimal (or +N: N cycles from now), then the bytes in hex"


def fresh(board):
    require_builds([board])
    return SimBoard(board, trace=True, control=True)


def wait_events(sim, kind, count, timeout=REPLY_TIMEOUT, settle=16 * BYTE):
    """The trace's `kind` events once there are `count` of them, and still
    `count` after `settle` more simulated cycles (none comes late). The
    simulator writes an event before it answers a later `wait`, so simulated
    time decides; the wall-clock deadline only bounds a run that hangs."""
    ctl = sim.control
    deadline = time.monotonic() + timeout
    while len(sim.trace_events(kinds=[kind])) < count:
        assert time.monotonic() < deadline, (kind, len(sim.trace_events(kinds=[kind])), count)
        ctl.wait(BYTE)
    ctl.wait(settle)
    events = sim.trace_events(kinds=[kind])
    assert len(events) == count, (kind, len(events), count)
    return events


def error(ctl, line):
    with pytest.raises(SimControlError) as exc:
        ctl.request(line)
    return str(exc.value)


def injected_request(board):
    """In a fresh simulator: REQUEST scheduled at AT; (rx's answer, the reply
    line, every uart event of the trace as (cycle, kind, byte))."""
    with fresh(board) as sim:
        ctl = sim.control
        assert ctl.time() < AT, "the simulator ran past AT before the test asked"
        end = ctl.rx(AT, REQUEST)
        with serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
            reply = port.readline()
        uart = [(e.cycle, e.kind, e.fields[0]) for e in sim.trace_events(kinds=["uart"])]
        assert sim.stop() == 0
    return end, reply, uart


@pytest.mark.parametrize("board", BOARDS)
def test_injected_request_is_exact_and_repeats_in_a_fresh_simulator(board):
    first = injected_request(board)
    end, reply, uart = first
    # the request's bytes reach the receiver one byte time apart from AT on,
    # and rx answers the last one's cycle
    assert end == AT + BYTE * len(REQUEST)
    rx = [(cycle, byte) for cycle, kind, byte in uart if kind == "uart rx"]
    assert rx == [(AT + BYTE * (i + 1), "%02X" % c) for i, c in enumerate(REQUEST)]
    # the reply: every byte of it starts after the request's last stop bit
    assert re.fullmatch(rb"SWAASR[0-9A-F]{2}P\r\n", reply), reply
    tx = [(cycle, byte) for cycle, kind, byte in uart if kind == "uart tx"]
    assert bytes(int(b, 16) for _, b in tx) == reply
    assert tx[0][0] > end
    assert len(uart) == len(rx) + len(tx)
    # a second fresh simulator: every byte at the same cycle, both directions
    assert injected_request(board) == first


def test_requests_scheduled_back_to_back_and_in_several_words():
    with fresh("m32d") as sim, serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
        ctl = sim.control
        assert ctl.time() < AT
        assert ctl.request("rx %d 56" % AT) == str(AT + BYTE)
        # the next byte may start exactly where the last one ends
        assert ctl.request("rx %d 0d 56 0D" % (AT + BYTE)) == str(AT + 4 * BYTE)
        assert port.readline() == b"V1.1\r\n"
        assert port.readline() == b"V1.1\r\n"
        rx = wait_events(sim, "uart rx", 4)
        assert [(e.cycle, e.fields[0]) for e in rx] == [
            (AT + BYTE, "56"), (AT + 2 * BYTE, "0D"), (AT + 3 * BYTE, "56"), (AT + 4 * BYTE, "0D")]


def test_pty_bytes_queue_behind_scheduled_bytes():
    """The PC's bytes stream over the line; `V CR` scheduled in their midst
    gets exactly its cycles, the PC's bytes go around it, none is lost."""
    filler = b" " * 20000                  # 12.8 M cycles on the wire
    with fresh("m32d") as sim, serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
        ctl = sim.control
        # the PC's bytes first, waited for in simulated time until the
        # simulator has taken some (they stream for 12.8 M cycles); then V CR
        # 1 s simulated ahead (`rx +N`), in the middle of them whatever the load
        before = ctl.line()["pty"]
        # the pty holds a few kB: the write returns once most is taken
        writer = threading.Thread(target=port.write, args=(filler,))
        writer.start()
        try:
            ctl.wait_taken(before + 1, step=100)
            end = ctl.rx_after(F_CPU, b"V\r")
        finally:
            writer.join()
        at = end - 2 * BYTE
        rx = wait_events(sim, "uart rx", len(filler) + 2, timeout=30)
        # the line overflowed the firmware's buffer long before the CR
        assert port.readline() == b"ERROR 04\r\n"
        assert board_sent(sim, 0) == b"ERROR 04\r\n"     # and nothing else, by now
    cycles = [e.cycle for e in rx]
    data = bytes(int(e.fields[0], 16) for e in rx)
    i = cycles.index(at + BYTE)
    assert data[i:i + 2] == b"V\r" and cycles[i + 1] == at + 2 * BYTE
    assert data[:i] + data[i + 2:] == filler
    # the PC's stream surrounds the scheduled bytes: the byte before ends by
    # `at` (the next would not have fitted), the one after starts at their end
    assert 0 < i < len(filler)
    assert at - BYTE < cycles[i - 1] <= at
    assert cycles[i + 2] == at + 3 * BYTE
    # one byte on the wire at a time
    assert min(b - a for a, b in zip(cycles, cycles[1:])) == BYTE


def test_bad_rx_requests_are_refused_and_schedule_nothing():
    with fresh("m32d") as sim:
        ctl = sim.control
        now = ctl.time()
        for line in ("rx", "rx %d" % FAR, "rx -5 56", "rx 12x 56", "rx 0x10 56"):
            assert error(ctl, line) == USAGE, line
        for word in ("5", "0G", "560", "x"):
            assert error(ctl, "rx %d 56 %s" % (FAR, word)) == \
                "ERR rx: bad hex '%s' (pairs of hex digits)" % word
        assert error(ctl, "rx %d 1 2 3 4 5 6 7" % FAR) == "ERR too many arguments"
        m = re.fullmatch(r"ERR rx: cycle 10 is past \(now (\d+)\)", error(ctl, "rx 10 56"))
        assert m and int(m[1]) >= now
        assert error(ctl, "rx %d 56" % (1 << 42)) == \
            "ERR rx: cycle %d is more than %d cycles ahead" % (1 << 42, 1 << 40)
        # a scheduled byte takes the line: nothing else may start before it ends
        assert ctl.rx(FAR, b"V") == FAR + BYTE
        for at in (FAR, FAR + BYTE - 1, FAR - 1):
            assert error(ctl, "rx %d 0D" % at) == \
                "ERR rx: the line is busy until cycle %d" % (FAR + BYTE), at
        # fill the schedule (32768 bytes): the request that does not fit is
        # refused whole, and the room is still there afterwards
        at, room = FAR + BYTE, 32768 - 1
        while room > RX_MAX:
            assert ctl.rx(at, b" " * RX_MAX) == at + RX_MAX * BYTE
            at, room = at + RX_MAX * BYTE, room - RX_MAX
        assert error(ctl, "rx %d %s" % (at, "20" * (room + 1))) == \
            "ERR rx: too many bytes: %d, room for %d (at most 32768 scheduled)" % (room + 1, room)
        assert ctl.rx(at, b" " * room) == at + room * BYTE
        assert error(ctl, "rx %d 20" % (at + room * BYTE)) == \
            "ERR rx: too many bytes: 1, room for 0 (at most 32768 scheduled)"
        with pytest.raises(ValueError):
            ctl.rx(at + room * BYTE, b"")
        for line in ("rx + 56", "rx ++5 56", "rx +-5 56", "rx +x 56"):
            assert error(ctl, line) == USAGE, line
        assert error(ctl, "rx +%d 56" % (1 << 42)) == \
            "ERR rx: +%d is more than %d cycles ahead" % (1 << 42, 1 << 40)
        assert "rx CYCLE HEX..." in ctl.request("help")
        assert sim.running
        assert sim.stop() == 0


def test_rx_after_counts_from_the_cycle_it_is_answered_at():
    """`rx +N`: the first start bit N cycles after the cycle the request is
    answered at, here the end of the `wait` before it in the same batch."""
    with fresh("m32d") as sim:
        ctl = sim.control
        woke, end, now = ctl.requests(["wait 1000", "rx +5000 56 0D", "time"])
        assert int(end) == int(woke) + 5000 + 2 * BYTE == int(now) + 5000 + 2 * BYTE
        ctl.wait(5000 + 2 * BYTE + 100)           # from a cycle >= now: past end
        rx = sim.trace_events(kinds=["uart rx"])
        assert [(e.cycle, e.fields[0]) for e in rx] == \
            [(int(end) - BYTE, "56"), (int(end), "0D")]
        later = ctl.rx_after(10, b"\r")
        assert later >= int(end) + 100 + 10 + BYTE
