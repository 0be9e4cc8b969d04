"""protocol.py without a board: formatting, parsing, errors, limits."""

import pytest

from orfa import protocol as p
from orfa.protocol import Read, ReadResult, Write, WriteResult


# --- formatting ---------------------------------------------------------------

def test_simple_requests():
    assert p.format_version() == "V"
    assert p.format_clear() == "X"
    assert p.format_local_address() == "L"
    assert p.format_local_address(0x20) == "L20"
    assert p.format_local_address(0x21) == "L21"
    assert p.format_clock() == "C"
    assert p.format_clock(0x190) == "C0190"
    assert p.format_clock(1) == "C0001"
    assert p.format_clock(0xFFFF) == "CFFFF"


@pytest.mark.parametrize("bad", [0x00, 0x01, -1, 0x100, None.__class__])
def test_local_address_refused(bad):
    with pytest.raises((ValueError, TypeError)):
        p.format_local_address(bad)


@pytest.mark.parametrize("bad", [0, -1, 0x10000, 1.5])
def test_clock_refused(bad):
    with pytest.raises(ValueError):
        p.format_clock(bad)


def test_transaction_write_and_multistart():
    assert p.format_transaction([Write(0x10, bytes([0x20, 0x00, 0x11, 0x12]))]) == "S1020001112P"
    assert p.format_transaction([Write(0xA0, b"\x10"), Read(0xA0, 4)]) == "SA010SA104P"
    assert p.format_transaction([Write(0x10)]) == "S10P"              # address probe
    assert p.format_transaction([Read(0x11, 3)]) == "S1103P"


def test_frame_address_bit0_is_set_by_the_frame_kind():
    assert p.format_transaction([Write(0xA1, b"\x01")]) == "SA001P"
    assert p.format_transaction([Read(0xA0, 1)]) == "SA101P"


def test_frame_checks():
    with pytest.raises(ValueError):
        Read(0xA0, 0)
    with pytest.raises(ValueError):
        Read(0xA0, 256)
    with pytest.raises(ValueError):
        Write(0x100)
    with pytest.raises(ValueError):
        Write(0xA0, [0x100])
    with pytest.raises(ValueError):
        p.format_transaction([])
    with pytest.raises(TypeError):
        p.format_transaction(["SA0P"])


def test_request_limit_edges():
    assert p.check_request("V" + " " * 127) == "V" + " " * 127
    with pytest.raises(p.LimitError) as exc:
        p.check_request("V" + " " * 128)
    assert exc.value.code == 4
    assert isinstance(exc.value, p.DataError)
    with pytest.raises(ValueError):
        p.check_request("V\nV")
    with pytest.raises(ValueError):
        p.check_request("V\r")
    with pytest.raises(ValueError):
        p.check_request("V\u00e9")
    assert p.encode_request("V") == b"V\n"


def test_transaction_request_limit():
    # "S" + addr + 2 digits per byte + "P": 62 bytes make 128 characters.
    line = p.format_transaction([Write(0xA0, bytes(62))])
    assert len(line) == 128
    with pytest.raises(p.LimitError):
        p.format_transaction([Write(0xA0, bytes(63))])


def test_transaction_reply_limit():
    # "SR" + 2 digits per byte + "P": 62 bytes make a 127-character reply.
    assert p.reply_length([Read(0xA0, 62)]) == 127
    assert p.format_transaction([Read(0xA0, 62)]) == "SA13EP"
    with pytest.raises(p.LimitError):
        p.format_transaction([Read(0xA0, 63)])
    # ten introspection records: SWAA + SR + 120 digits + P = 127
    frames = [Write(0xAA, b"\x00\x01"), Read(0xAA, 60)]
    assert p.reply_length(frames) == 127
    assert p.format_transaction(frames) == "SAA0001SAB3CP"
    with pytest.raises(p.LimitError):
        p.format_transaction([Write(0xAA, b"\x00\x01"), Read(0xAA, 61)])


def test_register_frames():
    assert p.register_write_frames(0xAA, 0x00, [0x01]) == [Write(0xAA, b"\x00\x01")]
    assert p.register_read_frames(0xAA, 0x00, 6) == [Write(0xAA, b"\x00"), Read(0xAA, 6)]
    assert p.format_transaction(p.register_read_frames(0x10, 0x20, 3)) == "S1020S1103P"


# --- parsing ------------------------------------------------------------------

def test_parse_simple_replies():
    assert p.parse_version("V1.1\r\n") == "1.1"
    assert p.parse_version(b"V1.1\r\n") == "1.1"
    assert p.parse_clear("X") is None
    assert p.parse_local_address("LAA") == 0xAA
    assert p.parse_clock("C0063\r\n") == 0x63


@pytest.mark.parametrize("parse, reply", [
    (p.parse_version, "V"), (p.parse_version, "X"), (p.parse_clear, "XX"),
    (p.parse_local_address, "LA"), (p.parse_local_address, "Laa"),
    (p.parse_clock, "C63"), (p.parse_clock, "C00630"),
    (p.parse_transaction, "SWAP "), (p.parse_transaction, "SWA"),
    (p.parse_transaction, "SR1P"), (p.parse_transaction, "SWBP"),
    (p.parse_transaction, "SRP"), (p.parse_transaction, "P"),
    (p.parse_transaction, "ERROR 6"), (p.parse_transaction, "ERROR 0G"),
    (p.parse_transaction, b"SW\xffP"),
])
def test_unparseable_replies(parse, reply):
    with pytest.raises(p.ProtocolError):
        parse(reply)


def test_parse_transaction():
    assert p.parse_transaction("SWAAAAP") == [WriteResult(4)]
    assert p.parse_transaction("SWP") == [WriteResult(0)]
    assert p.parse_transaction("SR0102ABP") == [ReadResult(b"\x01\x02\xab")]
    assert p.parse_transaction("SWASR0102ABCDP\r\n") == [
        WriteResult(1), ReadResult(b"\x01\x02\xab\xcd")]
    # hex data full of A's right after a write frame stays unambiguous
    assert p.parse_transaction("SWAASRAAAASWAP") == [
        WriteResult(2), ReadResult(b"\xaa\xaa"), WriteResult(1)]


def test_parse_transaction_checks_frames():
    frames = [Write(0xA0, b"\x10"), Read(0xA0, 2)]
    assert p.parse_transaction("SWASR0102P", frames) == [WriteResult(1), ReadResult(b"\x01\x02")]
    for reply in ("SWAASR0102P", "SWASR01P", "SWAP", "SR0102SWAP", "SWASR0102SWP"):
        with pytest.raises(p.ProtocolError):
            p.parse_transaction(reply, frames)


def test_reply_over_limit_is_a_protocol_error():
    with pytest.raises(p.ProtocolError):
        p.parse_transaction("SR" + "00" * 63 + "P")
    assert len(p.parse_transaction("SR" + "00" * 62 + "P")[0].data) == 62


# --- errors -------------------------------------------------------------------

@pytest.mark.parametrize("code, cls", [
    (1, p.InternalError), (2, p.UnknownCommandError), (3, p.HexError),
    (4, p.DataError), (5, p.IncompleteError), (6, p.AddressNackError),
    (7, p.DataNackError),
])
def test_error_replies(code, cls):
    reply = "ERROR %02X\r\n" % code
    for parse in (p.parse_version, p.parse_clock, p.parse_transaction, p.check_error):
        with pytest.raises(cls) as exc:
            parse(reply)
        assert exc.value.code == code
        assert isinstance(exc.value, p.OrfaError)
        assert str(exc.value) == "ERROR %02X" % code
        assert not isinstance(exc.value, p.ProtocolError)


def test_error_codes_enum():
    """The firmware's names (SG_ERR_* of serialgate/sg_parse.h), from the map."""
    assert [(int(c), c.name) for c in p.ErrorCode] == [
        (1, "INTERNAL"), (2, "COMMAND"), (3, "HEX"), (4, "DATA"), (5, "NO_P"),
        (6, "ADDR_NACK"), (7, "DATA_NACK")]
    assert p.DataNackError.code is p.ErrorCode.DATA_NACK
    assert p.IncompleteError.code is p.ErrorCode.NO_P
    assert p.AddressNackError.code is p.ErrorCode(6)
    assert str(p.ErrorCode.ADDR_NACK) == "ADDR_NACK"
    assert "%02X" % p.ErrorCode.ADDR_NACK == "{:02X}".format(p.ErrorCode.ADDR_NACK) == "06"
    assert p.IncompleteError.__doc__ == \
        "ERROR 05 (NO_P): the line ended before the P of an I2C request."


def test_unknown_error_code():
    with pytest.raises(p.OrfaError) as exc:
        p.check_error("ERROR 2A")
    assert exc.value.code == 0x2A
    assert type(exc.value) is p.OrfaError


def test_protocol_error_has_no_code():
    assert p.ProtocolError("x").code is None
    assert issubclass(p.ReplyTimeout, p.ProtocolError)


# --- introspection records ----------------------------------------------------

def test_driver_records():
    rec = p.DriverRecord.parse(bytes([0x00, 0x20, 1, 0, 0x02, 0x08]))
    assert rec == p.DriverRecord(uid=0x0020, major=1, minor=0, start=2, count=8)
    recs = p.DriverRecord.parse_many(bytes.fromhex("000001000002" "002001000208"))
    assert [r.uid for r in recs] == [0x0000, 0x0020]
    with pytest.raises(p.ProtocolError):
        p.DriverRecord.parse_many(bytes(7))


# --- TWI clock rounding (docs/protocol.md) ------------------------------------

@pytest.mark.parametrize("khz, reply, twbr, twps", [
    (0x0064, 0x0063, 29, 0),     # reset default: 99.632 kHz
    (0x0190, 0x0170, 2, 0),      # 400 asked, 368.64 made
    (0xFFFF, 0x01CC, 0, 0),      # 460.8 kHz, the fastest
    (0x01CD, 0x01CC, 0, 0),      # 461 asked: 460.8 is not above
    (0x01CC, 0x0199, 1, 0),      # 460 asked: 460.8 is above, next is 409.6
    (0x0001, 0x0000, 230, 2),    # 0.9996 kHz rounds down to 0
    (0x0002, 0x0001, 115, 2),    # 1.9948 kHz
])
def test_twi_clock(khz, reply, twbr, twps):
    got_reply, hz, got_twbr, got_twps = p.twi_clock(khz)
    assert (got_reply, got_twbr, got_twps) == (reply, twbr, twps)
    assert hz <= khz * 1000
    assert hz == p.F_CPU / (16 + 2 * twbr * 4 ** twps)


def test_twi_clock_is_the_fastest_not_above():
    rates = sorted({p.F_CPU / (16 + 2 * b * 4 ** s) for b in range(256) for s in range(4)})
    for khz in list(range(1, 600)) + [1000, 0xFFFF]:
        best = max(r for r in rates if r <= khz * 1000)
        assert p.twi_clock(khz)[1] == best
