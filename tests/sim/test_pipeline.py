"""Requests back to back at the full line rate, without waiting for replies."""

import random

AREA = 0xA0               # this module's bytes of the simulated EEPROM: 0xA0-0xBF


def test_pipelined_requests_in_one_write(board):
    """240 requests in one write; each reply is no longer than its request, so
    the host never has 256 characters of requests unanswered (docs/protocol.md,
    "Flow")."""
    rng = random.Random(1)
    n = board.driver_count()
    rec1 = board.record(1).hex().upper().encode()
    board.eeprom_write(AREA, bytes(8))
    board.eeprom_write(AREA + 8, bytes(8))
    mem = bytearray(16)
    requests, replies = [], []
    for i in range(240):
        kind = i % 8
        if kind == 0:
            requests.append(b"V    ")
            replies.append(b"V1.1\r\n")
        elif kind == 1:
            requests.append(b"L   ")
            replies.append(b"LAA\r\n")
        elif kind == 2:
            requests.append(b"S AA 00 00 S AB 01 P")
            replies.append(b"SWAASR%02XP\r\n" % n)
        elif kind == 3:
            requests.append(b"S AA 00 01 S AB 06 P")
            replies.append(b"SWAASR" + rec1 + b"P\r\n")
        elif kind == 4:
            off, value = rng.randrange(16), rng.randrange(256)
            mem[off] = value
            requests.append(b"S A0 %02X %02X P" % (AREA + off, value))
            replies.append(b"SWAAP\r\n")
        elif kind == 5:
            off = rng.randrange(16)
            requests.append(b"S A0 %02X S A1 01 P" % (AREA + off))
            replies.append(b"SWASR%02XP\r\n" % mem[off])
        elif kind == 6:
            requests.append(b"C      ")
            replies.append(b"C0063\r\n")
        else:
            requests.append(b"Q 1 2 3 4")
            replies.append(b"ERROR 02\r\n")
    data = b"".join(r + b"\n" for r in requests)
    got = board.exchange(data, len(requests))
    got_lines = got.split(b"\r\n")[:-1]
    want_lines = b"".join(replies).split(b"\r\n")[:-1]
    for i, (g, w) in enumerate(zip(got_lines, want_lines)):
        assert g == w, "request %d %r: got %r, want %r" % (i, requests[i], g, w)
    assert got == b"".join(replies)
    board.assert_silent()
    assert board.eeprom_read(AREA, 16) == bytes(mem)


def test_pipelined_short_requests(board):
    """Under 256 characters unanswered: 60 `V` requests (120 characters)."""
    assert board.exchange(b"V\n" * 60, 60) == b"V1.1\r\n" * 60
    board.assert_silent()


def test_receive_overflow_is_error_04_never_garbage(board):
    """Replies 6x longer than requests overflow the 256-character buffer; a
    request that lost characters (even all of them) is ERROR 04, every other
    reply is exact, and every request gets exactly one reply."""
    board.record(1)
    request = b"S AA 00 01 S AB 3C P\n"               # 21 characters, 129 back
    want = board.ask(request[:-1].decode())
    assert len(want) == 129
    board.gw.send(request * 100)
    got = board.read_lines(100)
    board.assert_silent()                             # and not one more
    lines = got.split(b"\r\n")
    assert lines[-1] == b"", got[-200:]
    lines = lines[:-1]
    assert len(lines) == 100
    bad = [line for line in lines if line + b"\r\n" != want and line != b"ERROR 04"]
    assert bad == []
    assert b"ERROR 04" in lines                       # the buffer did overflow
    assert board.ask("V") == b"V1.1\r\n"
    assert board.ask(request[:-1].decode()) == want


LONG = b"S AA 00 01 S AB 3C P\r"                      # 21 characters, 129 back


def test_overflow_of_empty_lines_only_adds_no_reply(board):
    """Issue 8: the overflow loses only line ends of empty lines: four long
    requests, 330 empty lines and V are five requests, five replies (it had
    been six: an ERROR 04 for the lost empty lines)."""
    want = board.ask(LONG[:-1].decode())
    board.gw.send(LONG * 4 + b"\n" * 330 + b"V\r")
    lines = board.read_lines(5).split(b"\r\n")[:-1]
    assert lines[:4] == [want[:-2]] * 4
    assert lines[4] in (b"V1.1", b"ERROR 04")         # V, or V lost characters
    # the next reply is the next request's: not a sixth for the five (an L,
    # not the V sentinel, so that a late V1.1 cannot pass for it)
    assert board.ask("L") == b"LAA\r\n"


def test_idle_line_after_an_overflow_of_empty_lines(board):
    """Issue 8: eleven long requests then 250 line ends: eleven replies, and
    the next request on the quiet line is served (it had got ERROR 04)."""
    want = board.ask(LONG[:-1].decode())
    board.gw.send(LONG * 11 + b"\n" * 250)
    lines = board.read_lines(11).split(b"\r\n")[:-1]
    assert all(line in (want[:-2], b"ERROR 04") for line in lines), lines
    board.assert_silent()                             # V now: V1.1, nothing before
    assert board.ask("V") == b"V1.1\r\n"


def test_long_lines_of_spaces_are_empty(board):
    """docs/protocol.md, "The line": a line of nothing but spaces is empty,
    whatever its length."""
    board.gw.send(b" " * 129 + b"\r" + b" " * 300 + b"\n" + b" " * 1000 + b"\r\n")
    board.assert_silent()
    assert board.ask(" " * 200 + "V") == b"ERROR 04\r\n"   # a request over 128
