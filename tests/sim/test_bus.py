"""I2C requests against the simulated 24C02 at 0xA0, seen from the serial
line and from the simulator's bus trace."""

import pytest

from orfa import protocol as p

AREA = 0x60               # this module's bytes of the simulated EEPROM: 0x60-0x9F


def test_address_probe(board):
    mark = board.mark()
    assert board.ask("S A0 P") == b"SWP\r\n"
    assert board.bus(mark) == [("start",), ("addr", "A0", "ack"), ("stop",)]


def test_address_probe_absent(board):
    mark = board.mark()
    assert board.ask("S A2 P") == b"ERROR 06\r\n"
    assert board.bus(mark) == [("start",), ("addr", "A2", "nack"), ("stop",)]


def test_write_then_multistart_read(board):
    mark = board.mark()
    assert board.ask("S A0 %02X 11 22 33 P" % AREA) == b"SWAAAAP\r\n"
    assert board.bus(mark) == [
        ("start",), ("addr", "A0", "ack"), ("write", "%02X" % AREA, "ack"),
        ("write", "11", "ack"), ("write", "22", "ack"), ("write", "33", "ack"),
        ("stop",)]
    mark = board.mark()
    assert board.ask("S A0 %02X S A1 03 P" % AREA) == b"SWASR112233P\r\n"
    assert board.bus(mark) == [
        ("start",), ("addr", "A0", "ack"), ("write", "%02X" % AREA, "ack"),
        ("start",), ("addr", "A1", "ack"),
        ("read", "11", "ack"), ("read", "22", "ack"), ("read", "33", "nack"),
        ("stop",)]


def test_manual_example_shapes(board):
    # `S 10 20 00 11 12 P` gives SWAAAAP: the register byte counts
    assert board.ask("S A0 %02X 00 11 12 P" % (AREA + 8)) == b"SWAAAAP\r\n"
    assert board.ask("S A0 %02X S A1 03 P" % (AREA + 8)) == b"SWASR001112P\r\n"


def test_read_continues_at_the_current_address(board):
    board.eeprom_write(AREA + 16, b"\xa1\xa2\xa3\xa4")
    assert board.ask("S A0 %02X S A1 02 P" % (AREA + 16)) == b"SWASRA1A2P\r\n"
    assert board.ask("S A1 02 P") == b"SRA3A4P\r\n"


def test_several_read_frames_in_one_request(board):
    board.eeprom_write(AREA + 24, b"\x01\x02\x03\x04\x05\x06")
    reply = board.ask("S A0 %02X S A1 02 S A1 01 S A1 03 P" % (AREA + 24))
    assert reply == b"SWASR0102SR03SR040506P\r\n"


def test_write_frames_and_read_in_one_request(board):
    """Frames run in order with repeated STARTs and one STOP; the reply carries
    the bytes the bus saw. The simulated EEPROM stores each byte when it is
    acknowledged (docs/simulator.md), so the read sees C1 C2."""
    board.eeprom_write(AREA + 32, b"\x5a\xa5")
    mark = board.mark()
    reply = board.ask("S A0 %02X C1 C2 S A0 %02X S A1 02 P" % (AREA + 32, AREA + 32))
    bus = board.bus(mark)
    a = "%02X" % (AREA + 32)
    assert bus[:10] == [
        ("start",), ("addr", "A0", "ack"), ("write", a, "ack"), ("write", "C1", "ack"),
        ("write", "C2", "ack"), ("start",), ("addr", "A0", "ack"), ("write", a, "ack"),
        ("start",), ("addr", "A1", "ack")]
    assert [e[0] for e in bus[10:]] == ["read", "read", "stop"]
    assert (bus[10][2], bus[11][2]) == ("ack", "nack")
    assert bus[10][1] + bus[11][1] == "C1C2"
    assert reply == b"SWAAASWASR%s%sP\r\n" % (bus[10][1].encode(), bus[11][1].encode())


def test_page_wrap(board):
    page = AREA + 40
    board.eeprom_write(page, bytes(8))
    data = bytes(range(0xB0, 0xBA))                 # 10 bytes from page+5
    assert board.ask("S A0 %02X %s P" % (page + 5, data.hex(" ").upper())) \
        == b"SW" + b"A" * 11 + b"P\r\n"
    mem = bytearray(8)
    for i, byte in enumerate(data):
        mem[(5 + i) % 8] = byte
    assert board.eeprom_read(page, 8) == bytes(mem)
    assert mem == bytes([0xB3, 0xB4, 0xB5, 0xB6, 0xB7, 0xB8, 0xB9, 0xB2])


def test_read_wraps_at_256(board):
    board.eeprom_write(0xF8, bytes(range(0xF0, 0xF8)))
    board.eeprom_write(0x00, bytes([0x0A, 0x0B]))
    assert board.ask("S A0 FE S A1 04 P") == b"SWASRF6F70A0BP\r\n"


def test_gateway_methods_against_the_eeprom(board):
    gw = board.gw
    gw.write_register(0xA0, AREA + 48, b"\x42\x43")
    assert gw.read_register(0xA0, AREA + 48, 2) == b"\x42\x43"
    assert gw.probe(0xA0) is True
    assert gw.probe(0xA4) is False
    with pytest.raises(p.AddressNackError) as exc:
        gw.read(0xA4, 1)
    assert exc.value.code == 6
    assert gw.version() == "1.1"
    assert gw.clock() == 0x63
    assert gw.local_address() == 0xAA


def test_local_frames_mixed_with_bus_frames(board):
    board.eeprom_write(AREA + 56, b"\x77")
    count = board.driver_count()
    mark = board.mark()
    reply = board.ask("S A0 %02X S AA 00 00 S AB 01 S A1 01 P" % (AREA + 56))
    assert reply == b"SWASWAASR%02XSR77P\r\n" % count
    assert board.bus(mark) == [
        ("start",), ("addr", "A0", "ack"), ("write", "%02X" % (AREA + 56), "ack"),
        ("start",), ("addr", "A1", "ack"), ("read", "77", "nack"), ("stop",)]


def test_local_request_makes_no_bus_traffic(board):
    mark = board.mark()
    assert board.ask("S AA 00 00 S AB 01 P")[:6] == b"SWAASR"
    assert board.ask("S AA P") == b"SWP\r\n"
    assert board.ask("V") == b"V1.1\r\n"
    assert board.ask("L") == b"LAA\r\n"
    assert board.bus(mark) == []


def test_uart_bytes_arrive_640_cycles_apart(board):
    """8N1 at 115200 baud and 7.3728 MHz: 10 bits of 64 cycles per byte."""
    mark = board.mark()
    data = b"S A0 %02X S A1 01 P\n" % AREA
    board.exchange(data, 1)
    rx = board.events(mark, ["uart rx"])
    assert [int(e.fields[0], 16) for e in rx] == list(data)
    assert [b.cycle - a.cycle for a, b in zip(rx, rx[1:])] == [640] * (len(data) - 1)


def test_reply_follows_its_terminator(board):
    mark = board.mark()
    board.exchange(b"V\n", 1)
    events = board.events(mark, ["uart"])
    assert [(e.kind, e.fields[0]) for e in events] == (
        [("uart rx", "56"), ("uart rx", "0A")]
        + [("uart tx", "%02X" % b) for b in b"V1.1\r\n"])
    assert events[2].cycle > events[1].cycle
    tx = events[2:]
    # bytes leave no faster than the wire allows
    assert all(b.cycle - a.cycle >= 640 for a, b in zip(tx, tx[1:]))


@pytest.mark.parametrize("khz", [0x64, 0x0A, 0xC8, 0x190], ids=lambda k: "C%04X" % k)
def test_bus_clock_from_the_trace(board, khz):
    """A byte and its ACK take 9 SCL periods; the period follows `C<freq>`."""
    reply = board.ask("C%04X" % khz)
    assert reply == b"C%04X\r\n" % p.twi_clock(khz)[0]
    _, hz, twbr, twps = p.twi_clock(khz)
    period = 16 + 2 * twbr * 4 ** twps
    mark = board.mark()
    assert board.ask("S A0 %02X 00 00 00 00 P" % (AREA + 8)) == b"SWAAAAAP\r\n"
    writes = [e for e in board.events(mark, ["twi write"])]
    assert len(writes) == 5
    gaps = [b.cycle - a.cycle for a, b in zip(writes, writes[1:])]
    assert min(gaps) >= 9 * period, gaps
    # the firmware reacts within 200 cycles, far less than the next slower clock
    assert max(gaps) < 9 * period + 200, gaps


def test_data_byte_not_acknowledged(board):
    """ERROR 07: the device took its address and the word address, refused
    the data byte; STOP follows at once and only the error is replied."""
    mark = board.mark()
    assert board.ask("S A6 10 55 66 P") == b"ERROR 07\r\n"
    assert board.bus(mark) == [
        ("start",), ("addr", "A6", "ack"), ("write", "10", "ack"),
        ("write", "55", "nack"), ("stop",)]


def test_data_nack_after_an_earlier_frame(board):
    """Frames before the failing one took effect (as on any I2C bus); the
    reply is only the error."""
    board.eeprom_write(AREA + 40, b"\x00")
    mark = board.mark()
    assert board.ask("S A0 %02X 77 S A6 10 55 P" % (AREA + 40)) == b"ERROR 07\r\n"
    assert board.bus(mark) == [
        ("start",), ("addr", "A0", "ack"), ("write", "%02X" % (AREA + 40), "ack"),
        ("write", "77", "ack"), ("start",), ("addr", "A6", "ack"), ("write", "10", "ack"),
        ("write", "55", "nack"), ("stop",)]
    assert board.eeprom_read(AREA + 40, 1) == b"\x77"
    # and the protected part still reads
    assert board.ask("S A6 10 S A7 01 P") == b"SWASRFFP\r\n"
