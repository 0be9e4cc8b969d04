"""The gateway's own register map at the local address (docs/registers.md):
introspection and the status register."""

from orfa import protocol as p

from orfa.boards import BOARD_UIDS

OK, BAD_LENGTH, BAD_VALUE, READ_WRAPPED = 0x00, 0x01, 0x02, 0x06


def test_driver_count(board):
    n = board.driver_count()
    assert 1 <= n <= len(BOARD_UIDS[board.board])
    assert board.ask("S AA 00 00 S AB 01 P") == b"SWAASR%02XP\r\n" % n


def test_first_record_is_introspection(board):
    assert board.ask("S AA 00 01 S AB 06 P") == b"SWAASR000001000002P\r\n"


def test_records_are_consistent(board):
    n = board.driver_count()
    records = [p.DriverRecord.parse(board.record(i)) for i in range(1, n + 1)]
    assert records[0] == p.DriverRecord(0x0000, 1, 0, 0x00, 0x02)
    for prev, rec in zip(records, records[1:]):
        assert rec.start == prev.start + prev.count, records
        assert rec.count >= 1, rec
    uids = [r.uid for r in records]
    assert len(set(uids)) == n
    # the drivers built in are the board's, in the board's order
    allowed = BOARD_UIDS[board.board]
    assert uids == [u for u in allowed if u in uids], [hex(u) for u in uids]


def test_auto_increment_over_all_records(board):
    n = board.driver_count()
    singles = b"".join(board.record(i) for i in range(1, n + 1))
    k = min(n, 10)
    reply = board.ask("S AA 00 01 S AB %02X P" % (6 * k))
    assert reply == b"SWAASR" + singles[:6 * k].hex().upper().encode() + b"P\r\n"


def test_count_read_moves_nothing(board):
    """docs/registers.md: reading the count moves nothing; every later read frame (and
    every further byte of a longer one) gives the count again, as ORFA 0.7.5
    does, until another number is written."""
    n = board.driver_count()
    assert board.ask("S AA 00 00 S AB 03 P") == b"SWAASR%02X%02X%02XP\r\n" % (n, n, n)
    assert board.ask("S AB 01 P") == b"SR%02XP\r\n" % n
    assert board.ask("S AB 01 S AB 01 P") == b"SR%02XSR%02XP\r\n" % (n, n)
    assert board.ask("S AA 00 01 S AB 06 P") == b"SWAASR%sP\r\n" % (
        board.record(1).hex().upper().encode())


def test_reading_past_the_last_driver_wraps(board):
    n = board.driver_count()
    last, first = board.record(n), board.record(1)
    assert board.status() == OK
    reply = board.ask("S AA 00 %02X S AB 0C P" % n)
    assert reply == b"SWAASR%s%sP\r\n" % (last.hex().upper().encode(),
                                          first.hex().upper().encode())
    assert board.status() == READ_WRAPPED
    assert board.status() == READ_WRAPPED      # reading the status keeps it


def test_driver_above_count_is_refused(board):
    n = board.driver_count()
    mark = board.mark()
    assert board.ask("S AA 00 %02X P" % (n + 1)) == b"ERROR 07\r\n"
    assert board.ask("S AB 06 P") == b"SR000001000002P\r\n"     # driver 1
    assert board.bus(mark) == []


def test_driver_above_count_status(board):
    n = board.driver_count()
    assert board.ask("S AA 00 %02X S AB 06 P" % (n + 1)) == b"ERROR 07\r\n"
    assert board.status() == BAD_VALUE
    assert board.status() == BAD_VALUE
    # selecting a register is not an access: the next read still gives driver 1
    assert board.ask("S AA 00 S AB 06 P") == b"SWASR000001000002P\r\n"
    assert board.status() == OK


def first_byte_after(board, request):
    """The reply to `request` and the cycles from its terminator reaching the
    board to the reply's first byte."""
    mark = board.mark()
    reply = board.ask(request)
    ev = board.events(mark, ["uart"])
    first = next(i for i, e in enumerate(ev) if e.kind == "uart tx")
    assert ev[first - 1].kind == "uart rx" and ev[first - 1].fields == ("0A",), ev[:first + 1]
    return reply, ev[first].cycle - ev[first - 1].cycle


def test_introspection_reply_starts_within_a_byte(board):
    """issue 20: the gateway's own introspection read cannot fail once the
    line is checked, so its reply starts before the frames run: within 640
    cycles (a byte at 115200), the reply the same as ever."""
    n = board.driver_count()
    reply, cycles = first_byte_after(board, "S AA 00 00 S AB 01 P")
    assert reply == b"SWAASR%02XP\r\n" % n and cycles <= 640
    reply, cycles = first_byte_after(board, "S AA 00 01 S AB 06 P")
    assert reply == b"SWAASR000001000002P\r\n" and cycles <= 640
    assert board.status() == OK


def test_driver_above_count_is_refused_whole(board):
    """The fast reply never starts for a request that fails: ERROR only."""
    n = board.driver_count()
    reply, _ = first_byte_after(board, "S AA 00 %02X S AB 06 P" % (n + 1))
    assert reply == b"ERROR 07\r\n"


def test_driver_ff_is_refused(board):
    assert board.ask("S AA 00 FF P") == b"ERROR 07\r\n"
    assert board.status() == BAD_VALUE


def test_introspection_write_of_two_bytes_is_refused(board):
    board.driver_count()
    assert board.status() == OK
    assert board.ask("S AA 00 01 02 P") == b"ERROR 07\r\n"
    assert board.status() == BAD_LENGTH


def test_status_after_a_good_access_is_ok(board):
    assert board.ask("S AA 00 FF P") == b"ERROR 07\r\n"
    assert board.status() == BAD_VALUE
    board.record(1)
    assert board.status() == OK


def test_selecting_a_register_does_not_change_status(board):
    assert board.ask("S AA 00 FF P") == b"ERROR 07\r\n"
    assert board.ask("S AA 00 P") == b"SWAP\r\n"
    assert board.status() == BAD_VALUE


def test_status_register_cannot_be_written(board):
    assert board.ask("S AA 01 00 P") == b"ERROR 07\r\n"
    assert board.ask("V") == b"V1.1\r\n"


def test_unmapped_register_is_not_acknowledged(board):
    n = board.driver_count()
    last = p.DriverRecord.parse(board.record(n))
    first_free = last.start + last.count
    mark = board.mark()
    assert board.ask("S AA %02X P" % first_free) == b"ERROR 07\r\n"
    assert board.ask("S AA %02X S AB 01 P" % first_free) == b"ERROR 07\r\n"
    assert board.ask("S AA FF 00 P") == b"ERROR 07\r\n"
    assert board.bus(mark) == []
    # the last mapped register is acknowledged
    assert board.ask("S AA %02X P" % (first_free - 1)) == b"SWAP\r\n"


def test_gateway_drivers_helper(board):
    n = board.driver_count()
    records = board.gw.drivers()
    assert len(records) == n
    assert [r for r in records] == [p.DriverRecord.parse(board.record(i))
                                    for i in range(1, n + 1)]


def test_the_board_map_is_what_the_firmware_answers(board):
    """The generated map (host/orfa/maps/<board>.json) against the running
    firmware: every record (UID, version, start, count) in order."""
    from orfa import boardmap
    m = boardmap.load(board.board)
    records = board.gw.drivers()
    assert [(r.uid, r.major, r.minor, r.start, r.count) for r in records] == \
        [(d.uid, d.major, d.minor, d.start, d.count) for d in m.drivers]
