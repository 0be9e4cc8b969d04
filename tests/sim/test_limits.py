"""Limits at their edges: 128-character requests, 127-character replies."""

import pytest

from orfa import protocol as p

EEPROM_AREA = 0x40        # this module's bytes of the simulated EEPROM: 0x40-0x5F


def eeprom_page_write(mem: bytearray, addr: int, data: bytes) -> None:
    """What a 24C02 does with a write at addr: wrap inside the 8-byte page."""
    page = addr & ~7
    for i, byte in enumerate(data):
        mem[page + (addr + i) % 8] = byte


def test_request_of_128_characters_is_accepted(board):
    line = "V" + " " * 127
    assert len(line) == p.MAX_REQUEST_CHARS
    assert board.ask(line) == b"V1.1\r\n"


def test_request_of_129_characters_is_refused(board):
    assert board.ask("V" + " " * 128) == b"ERROR 04\r\n"
    assert board.ask("V") == b"V1.1\r\n"


def test_128_character_write_is_executed(board):
    data = bytes(range(0x80, 0x80 + 61))
    line = "SA0%02X%sP" % (EEPROM_AREA, data.hex().upper())
    assert len(line) == 128
    mark = board.mark()
    assert board.ask(line) == b"SW" + b"A" * 62 + b"P\r\n"
    bus = board.bus(mark)
    assert bus[:3] == [("start",), ("addr", "A0", "ack"), ("write", "%02X" % EEPROM_AREA, "ack")]
    assert bus[3:-1] == [("write", "%02X" % b, "ack") for b in data]
    assert bus[-1] == ("stop",)
    mem = bytearray(256)
    eeprom_page_write(mem, EEPROM_AREA, data)
    assert board.eeprom_read(EEPROM_AREA, 8) == bytes(mem[EEPROM_AREA:EEPROM_AREA + 8])


def test_129_character_write_is_refused_and_not_executed(board):
    board.eeprom_write(EEPROM_AREA + 8, b"\x01\x02\x03\x04")
    line = "S A0 %02X 55 66 77 88 P" % (EEPROM_AREA + 8)
    line += " " * (129 - len(line))
    mark = board.mark()
    assert board.ask(line) == b"ERROR 04\r\n"
    assert board.bus(mark) == []
    assert board.eeprom_read(EEPROM_AREA + 8, 4) == b"\x01\x02\x03\x04"


def test_long_line_is_one_error(board):
    mark = board.mark()
    line = "S A0 %02X " % (EEPROM_AREA + 16) + "AB " * 150 + "P"
    assert board.exchange(line.encode() + b"\nV\n", 2) == b"ERROR 04\r\nV1.1\r\n"
    assert board.bus(mark) == []
    board.assert_silent()


def test_reply_of_127_characters_is_accepted(board):
    n = board.driver_count()
    reply = board.ask("S AA 00 01 S AB 3C P")      # ten records, wrapping
    assert len(reply) == p.MAX_REPLY_CHARS + 2
    assert reply[:6] == b"SWAASR" and reply[-3:] == b"P\r\n"
    records = bytes.fromhex(reply[6:-3].decode())
    # driver 1..n, then on with driver 1 again
    assert records == b"".join(board.record(i % n + 1) for i in range(10))


def test_eeprom_read_of_127_characters(board):
    mark = board.mark()
    reply = board.ask("S A0 %02X S A1 3C P" % EEPROM_AREA)   # SWA SR 120 digits P
    assert len(reply) == 126 + 2 and reply.startswith(b"SWASR") and reply.endswith(b"P\r\n")
    assert len([e for e in board.bus(mark) if e[0] == "read"]) == 60
    reply = board.ask("S A1 3E P")                            # SR 124 digits P
    assert len(reply) == 127 + 2 and reply.startswith(b"SR") and reply.endswith(b"P\r\n")


@pytest.mark.parametrize("request_", [
    "S AA 00 01 S AB 3D P",
    "S A1 3F P",
    "S A1 FF P",
    "S A0 %02X S A1 3D P" % EEPROM_AREA,     # 128 characters
    "S A1 1F S A1 1F P",                 # two frames of 64 characters
])
def test_reply_over_127_characters_is_refused(board, request_):
    mark = board.mark()
    assert board.ask(request_) == b"ERROR 04\r\n"
    assert board.bus(mark) == []


def test_two_read_frames_of_127_characters(board):
    reply = board.ask("S A1 1F S A1 1E P")
    assert len(reply) == 127 + 2 and reply.endswith(b"P\r\n")
