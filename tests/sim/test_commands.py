"""docs/protocol.md, the simple requests: V X L C, case, spaces, line ends."""

import pytest

from orfa import protocol as p


def test_version(board):
    assert board.ask("V") == b"V1.1\r\n"


def test_clear_bus(board):
    assert board.ask("X") == b"X\r\n"
    assert board.ask("V") == b"V1.1\r\n"


def test_local_address_default(board):
    assert board.ask("L") == b"LAA\r\n"


@pytest.mark.parametrize("request_, reply", [
    ("L20", b"L20\r\n"),
    ("L21", b"L20\r\n"),          # bit 0 ignored
    ("LFF", b"LFE\r\n"),
    ("L02", b"L02\r\n"),
    ("L03", b"L02\r\n"),
    ("l 5b", b"L5A\r\n"),
])
def test_set_local_address(board, request_, reply):
    assert board.ask(request_) == reply
    assert board.ask("L") == reply


@pytest.mark.parametrize("request_", ["L00", "L01"])
def test_local_address_zero_refused(board, request_):
    assert board.ask("L20") == b"L20\r\n"
    assert board.ask(request_) == b"ERROR 04\r\n"
    assert board.ask("L") == b"L20\r\n"


def test_local_address_moves_the_register_map(board):
    assert board.ask("L20") == b"L20\r\n"
    mark = board.mark()
    # the register map answers at 0x20 now, without bus traffic
    assert board.ask("S 20 00 00 S 21 01 P")[:6] == b"SWAASR"
    assert board.bus(mark) == []
    # and 0xAA is an ordinary (absent) bus device
    assert board.ask("S AA P") == b"ERROR 06\r\n"
    assert board.bus(mark) == [("start",), ("addr", "AA", "nack"), ("stop",)]


def test_clock_default(board):
    assert board.ask("C") == b"C0063\r\n"


@pytest.mark.parametrize("khz", [0x0064, 0x0190, 0xFFFF, 0x01CD, 0x01CC, 0x0001,
                                 0x0002, 0x000A, 0x0032, 0x00C8, 0x012C, 0x03E8],
                         ids=lambda k: "C%04X" % k)
def test_set_clock_rounding(board, khz):
    expect = ("C%04X\r\n" % p.twi_clock(khz)[0]).encode()
    assert board.ask("C%04X" % khz) == expect
    assert board.ask("C") == expect


@pytest.mark.parametrize("request_, reply", [
    ("C0190", b"C0170\r\n"),
    ("C 01 90", b"C0170\r\n"),
    ("CFFFF", b"C01CC\r\n"),
    ("C0001", b"C0000\r\n"),
    ("c01cc", b"C0199\r\n"),
])
def test_clock_examples(board, request_, reply):
    assert board.ask(request_) == reply


@pytest.mark.parametrize("request_, reply", [
    ("C0000", b"ERROR 04\r\n"),
    ("C01", b"ERROR 04\r\n"),
    ("C000100", b"ERROR 04\r\n"),
    ("C 006", b"ERROR 03\r\n"),
])
def test_clock_refused_keeps_clock(board, request_, reply):
    assert board.ask("C0032") == b"C0031\r\n"         # 49.816 kHz
    assert board.ask(request_) == reply
    assert board.ask("C") == b"C0031\r\n"


@pytest.mark.parametrize("request_, reply", [
    ("v", b"V1.1\r\n"),
    ("x", b"X\r\n"),
    ("l", b"LAA\r\n"),
    ("c", b"C0063\r\n"),
    ("s a0 p", b"SWP\r\n"),
    ("s a0 0a s a1 01 p", None),
    ("S a0 0A s A1 01 P", None),
])
def test_lower_case(board, request_, reply):
    got = board.ask(request_)
    if reply is None:
        assert got[:5] == b"SWASR" and got[7:] == b"P\r\n" and len(got) == 10
        assert got == board.ask("SA00ASA101P")
    else:
        assert got == reply


@pytest.mark.parametrize("request_, reply", [
    ("   V", b"V1.1\r\n"),
    ("V   ", b"V1.1\r\n"),
    (" L  20 ", b"L20\r\n"),
    ("S  A0   P  ", b"SWP\r\n"),
    ("SA0P", b"SWP\r\n"),
    ("S 1 0 P", b"ERROR 03\r\n"),       # never inside a byte
    ("V\t", b"ERROR 04\r\n"),           # TAB is not a space
    ("\tV", b"ERROR 02\r\n"),
])
def test_spaces(board, request_, reply):
    assert board.ask(request_) == reply


@pytest.mark.parametrize("data", [b"V\r", b"V\n", b"V\r\n"])
def test_terminators(board, data):
    assert board.exchange(data + b"L\n", 2) == b"V1.1\r\nLAA\r\n"
    board.assert_silent()


def test_mixed_terminators_in_one_write(board):
    data = b"V\rL\nC\r\nV\n\r"
    assert board.exchange(data + b"X\n", 5) == b"V1.1\r\nLAA\r\nC0063\r\nV1.1\r\nX\r\n"
    board.assert_silent()


def test_empty_lines_get_no_reply(board):
    assert board.exchange(b"\n\r\r\n   \n \r\nV\n", 1) == b"V1.1\r\n"
    board.assert_silent()


@pytest.mark.parametrize("comment", [b"#", b"# S A0 00 41 P", b"#V", b"#" + b"x" * 300])
def test_comment_gets_no_reply_and_does_nothing(board, comment):
    mark = board.mark()
    assert board.exchange(comment + b"\nV\n", 1) == b"V1.1\r\n"
    board.assert_silent()
    assert board.bus(mark) == []


def test_comment_must_start_the_line(board):
    assert board.ask("  # x") == b"ERROR 02\r\n"
    assert board.ask("V #") == b"ERROR 04\r\n"
