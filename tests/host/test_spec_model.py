"""The soak's reference model (tests/sim/spec_model.py) against the examples
of docs/protocol.md and docs/registers.md."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))

import pytest  # noqa: E402

from spec_model import (BoardModel, GatewayModel, OutOfScope, Record,  # noqa: E402
                        parse, twi_khz)

M32D = [Record(0x0000, 1, 0, 0x00, 2), Record(0x0020, 1, 1, 0x02, 8),
        Record(0x0001, 1, 1, 0x0A, 2), Record(0x0040, 1, 1, 0x0C, 2),
        Record(0x0060, 1, 1, 0x0E, 4), Record(0x0031, 2, 0, 0x12, 2),
        Record(0x0002, 1, 0, 0x14, 2)]
M128S = [Record(0x0000, 1, 0, 0x00, 2), Record(0x0021, 1, 1, 0x02, 4),
         Record(0x0001, 1, 1, 0x06, 2), Record(0x0040, 1, 1, 0x08, 2),
         Record(0x0030, 2, 0, 0x0A, 2), Record(0x0002, 1, 0, 0x0C, 2)]


def gateway():
    return GatewayModel(BoardModel("m32d", M32D), BoardModel("m128s", M128S), 0x10)


@pytest.mark.parametrize("khz,want", [(100, 0x63), (0x190, 0x170), (0xFFFF, 0x1CC),
                                      (1, 0)])
def test_clock(khz, want):
    assert twi_khz(khz) == want


@pytest.mark.parametrize("line,code", [
    ("Q", 2), ("  # x", 2), ("S 1 0 P", 3), ("S P", 3), ("S 1G", 3), ("LZZ", 3),
    ("L A", 3), ("C 006", 3), ("S 11 00 P", 4), ("S 11 P", 4), ("S 11 01 02 P", 4),
    ("L AA BB", 4), ("L00", 4), ("L01", 4), ("C 01", 4), ("C0000", 4), ("C 01 02 03", 4),
    ("V1", 4), ("X X", 4), ("S 10 P Q", 4), ("S 10 20", 5), ("S", 5),
    ("S AA 00 01 S AB 3D P", 4), ("V" + " " * 128, 4), ("Q" + " " * 200, 2),
])
def test_parse_errors(line, code):
    assert parse(line) == code


def test_no_reply():
    for line in ("", " ", " " * 500, "#", "# " + "x" * 300):
        assert parse(line) is None


def test_readme_sessions():
    g = gateway()
    for req, rep in [("V", "V1.1"), ("S AA 00 00 S AB 01 P", "SWAASR07P"),
                     ("S AA 00 01 S AB 06 P", "SWAASR000001000002P"),
                     ("S A0 10 48 69 P", "SWAAAP"), ("S A0 10 S A1 02 P", "SWASR4869P"),
                     ("S A2 P", "ERROR 06"), ("C", "C0063"), ("Q", "ERROR 02"),
                     ("S 10 00 00 S 11 01 P", "SWAASR06P"),
                     ("S 10 0B 40 05 DC P", "ERROR 07"), ("S 10 01 S 11 01 P", "SWASR02P"),
                     ("S 10 0B 03 05 P", "SWAAAP"), ("S 10 01 S 11 01 P", "SWASR01P"),
                     ("S 14 P", "ERROR 06"), ("L21", "L20"), ("S AA 00 P", "ERROR 06"),
                     ("S 20 00 P", "SWAP")]:
        assert g.reply(req) == rep.encode() + b"\r\n", req


def test_slave_table():
    """docs/registers.md, "On a slave board"."""
    g = gateway()
    for req, rep in [("S 10 0E 00 P", "ERROR 07"), ("S 10 01 S 11 01 P", "SWASR08P"),
                     ("S 10 0E P", "SWAP"), ("S 10 FE S 11 02 P", "SWASRFFFFP"),
                     ("S 10 06 S 11 03 P", "SWASRFFFFFFP"), ("S 10 01 S 11 01 P", "SWASR05P"),
                     ("S 10 00 01 02 03 P", "ERROR 07"), ("S 10 00 01 02 P", "SWAAAP"),
                     ("S 10 01 S 11 01 P", "SWASR01P"),
                     ("S AA 16 00 P", "ERROR 07"), ("S AA 0A S AB 01 P", "ERROR 06"),
                     ("S AA 00 01 02 P", "ERROR 07"), ("S AA 01 S AB 01 P", "SWASR01P")]:
        assert g.reply(req) == rep.encode() + b"\r\n", req


def test_out_of_scope_changes_nothing():
    g = gateway()
    assert g.reply("S A0 00 11 P") == b"SWAAP\r\n"
    with pytest.raises(OutOfScope):
        g.reply("S A0 00 22 P S AA 13 00 05 DC P".replace("P S", "S"))   # a servo would pulse
    assert g.reply("S A0 00 S A1 01 P") == b"SWASR11P\r\n"
