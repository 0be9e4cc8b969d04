"""orfa.decode on waveforms made here: a serial line's 8N1 frames at the
board's rate, and an I2C bus bit by bit (START, address + R/W, data,
ACK/NACK, repeated START, STOP, clock stretching, a START in the middle of
a byte); and sigrok's own decoders read the same from them."""

import subprocess
import sys
from pathlib import Path

import pytest

from orfa import boardmap, decode, waves
from wavegen import Bus, serial

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))
from sigrok import i2c_texts, needs_sigrok  # noqa: E402  (tests/sim's sigrok-cli helpers)

F = boardmap.F_CPU


def line(name, initial, edges, end=None):
    """A Wave over the whole of EDGES (and a little after)."""
    end = end if end is not None else (edges[-1][0] + 1000 if edges else 1000)
    return waves.window(name, initial, edges, 0, end)


@pytest.mark.parametrize("baud", [115200, 9600, 460800])
def test_uart_frames_at_the_boards_rate(baud):
    bit = F / baud                                 # 64 cycles at 115200, 768 at 9600
    data = b"S A0 10 48 69 P\r\nSWAAAP\r\n\x00\xff\x55"
    edges, starts = serial(data, bit, gap=3 * bit)
    frames = decode.uart(line("D0", 1, edges), bit)
    assert decode.bytes_of(frames) == data
    assert [f.start for f in frames] == starts
    assert all(f.end - f.start == round(10 * bit) for f in frames)
    assert [f.text for f in frames[:2]] == ["53", "20"]


def test_uart_back_to_back_and_a_framing_error():
    bit = F / 115200
    edges, _ = serial(b"OK", bit)                  # no gap: stop bit, then the next start
    frames = decode.uart(line("D1", 1, edges), bit)
    assert [(f.kind, f.value) for f in frames] == [("byte", 0x4F), ("byte", 0x4B)]
    bad, _ = serial(b"\x41", bit, stop=0)
    frames = decode.uart(line("D1", 1, bad), bit)
    assert [(f.kind, f.text) for f in frames] == [("framing error", "41")]


def test_uart_glitch_and_a_frame_cut_by_the_window():
    bit = F / 115200
    edges, _ = serial(b"\x41", bit, t=2000)
    glitch = [(1000, 0), (1010, 1)]                # low for 10 cycles: no start bit
    frames = decode.uart(line("D0", 1, glitch + edges), bit)
    assert [f.value for f in frames] == [0x41]
    cut = waves.window("D0", 1, edges, 0, 2000 + 5 * 64)
    assert decode.uart(cut, bit) == []
    # a line low from power-up that rises when the transmitter starts is no frame
    assert decode.uart(line("D1", 0, [(500, 1)]), bit) == []
    with pytest.raises(ValueError):
        decode.uart(line("D0", 1, edges), 0)


def test_char_names_the_protocols_bytes():
    assert [decode.char(b) for b in b"S A\r\n\x00\x7f"] == \
        ["S", "SP", "A", "CR", "LF", "00", "7F"]


def texts(frames):
    return " ".join(f.text for f in frames)


def test_i2c_write_of_an_eeprom():
    bus = Bus()
    bus.start()
    for b in (0xA0, 0x10, 0x41, 0x42):
        bus.byte(b, ack=True)
    bus.stop()
    frames = bus.frames()
    assert texts(frames) == "S A0 W A 10 A 41 A 42 A P"
    assert [f.kind for f in frames] == ["start", "address", "ack", "data", "ack", "data", "ack",
                                        "data", "ack", "stop"]
    assert decode.bytes_of(frames, ("address", "data")) == b"\xa0\x10\x41\x42"
    # a byte from its first bit's rising SCL to its 8th bit's falling SCL
    addr = frames[1]
    assert (addr.start, addr.end) == (bus.edges["scl"][1][0], bus.edges["scl"][16][0])
    assert frames[0].start == frames[0].end == bus.edges["sda"][0][0]


def test_i2c_read_with_a_repeated_start_and_the_masters_nack():
    bus = Bus()
    bus.start()
    bus.byte(0xA0, True)
    bus.byte(0x10, True)
    bus.restart()
    bus.byte(0xA1, True)
    bus.byte(0x41, True)                           # the master's ACK: more please
    bus.byte(0x42, False)                          # its NACK: the last one
    bus.stop()
    frames = bus.frames()
    assert texts(frames) == "S A0 W A 10 A Sr A1 R A 41 A 42 N P"
    assert [f.kind for f in frames if f.text in ("S", "Sr")] == ["start", "restart"]
    assert frames[-2].kind == "nack"


def test_i2c_absent_address_is_a_nack_then_stop():
    bus = Bus()
    bus.start()
    bus.byte(0xE0, ack=False)
    bus.stop()
    assert texts(bus.frames()) == "S E0 W N P"


def test_i2c_clock_stretching_delays_but_does_not_change_the_bytes():
    bus = Bus()
    bus.start()
    bus.byte(0x20, True)
    before = bus.t
    bus.byte(0x55, True, stretch=5000)             # the slave holds SCL low 5000 cycles
    bus.byte(0x0F, True, stretch=3)
    bus.stop()
    frames = bus.frames()
    assert texts(frames) == "S 20 W A 55 A 0F A P"
    data = frames[3]
    assert data.start >= before + 5000             # its first bit rose after the stretch
    assert data.end - data.start == 8 * 4 * bus.q - 2 * bus.q


def test_i2c_start_or_stop_in_the_middle_of_a_byte():
    bus = Bus()
    bus.start()
    bus.byte(0xA0, True)
    for b in (1, 0, 1):
        bus.bit(b)
    bus.restart()                                  # a START three bits into a byte
    bus.byte(0xA1, False)
    for b in (0, 1):
        bus.bit(b)
    bus.stop()                                     # a STOP two bits into the next
    frames = bus.frames()
    assert texts(frames) == "S A0 W A 3 bits Sr A1 R N 2 bits P"
    assert [f.value for f in frames if f.kind == "partial"] == [3, 2]


def test_i2c_reads_nothing_before_the_first_start():
    bus = Bus()
    for b in (1, 0, 1, 1):                         # clocking with SDA steady: no START
        bus.bit(1)
    bus.start()
    bus.byte(0x30, True)
    bus.stop()
    assert texts(bus.frames()) == "S 30 W A P"


# --- the same waveforms through sigrok's own decoders --------------------------

def sigrok(tmp_path, edges, names, decoder, annotations):
    """sigrok-cli's plain output for EDGES written as the simulator's VCD
    (every wire idle high from cycle 100, a last edge on `end` after them)."""
    from test_waves import make_vcd
    last = max(c for es in edges.values() for c, _ in es)
    changes = {n: [(100, 1)] + edges.get(n, []) for n in names}
    changes["end"] = [(last + 2000, 1)]
    src = tmp_path / "syn.vcd"
    src.write_text(make_vcd(changes, names=tuple(names) + ("end",)))
    r = subprocess.run(["sigrok-cli", "-i", str(src), "-I", "vcd", "-P", decoder,
                        "-A", annotations], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return r.stdout.splitlines()


@needs_sigrok
def test_i2c_reads_as_sigroks_i2c_decoder_does(tmp_path):
    bus = Bus(t=5000)
    bus.start()
    bus.byte(0xA0, True)
    bus.byte(0x10, True)
    bus.restart()
    bus.byte(0xA1, True)
    bus.byte(0x41, True, stretch=300)
    bus.byte(0x42, False)
    bus.stop()
    bus.t += 200
    bus.start()
    bus.byte(0xE0, False)
    bus.stop()
    got = sigrok(tmp_path, bus.edges, ("sda", "scl"),
                 "i2c:scl=scl:sda=sda:address_format=unshifted", "i2c=addr-data")
    theirs = i2c_texts(got)
    assert theirs == [f.text for f in bus.frames()]
    assert " ".join(theirs) == "S A0 W A 10 A Sr A1 R A 41 A 42 N P S E0 W N P"


@needs_sigrok
def test_uart_reads_as_sigroks_uart_decoder_does(tmp_path):
    edges, _ = serial(b"S A0 10 S A1 02 P\r\x00\xff", F // 115200, t=1000, gap=100)
    got = sigrok(tmp_path, {"D0": edges}, ("D0",), "uart:rx=D0:baudrate=115200", "uart=rx-data")
    ours = decode.uart(waves.window("D0", 1, edges, 0, edges[-1][0] + 1000), F / 115200)
    assert [int(line.split(": ")[1], 16) for line in got] == [f.value for f in ours]
