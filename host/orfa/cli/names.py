"""Names for what introspection reports: the board, each driver (from the
generated board maps, through orfa.Board)."""

from __future__ import annotations


def board_of(board) -> str:
    """"m32d (OR-AVR-M32-D)", or "unknown (UIDs ...)" when no map matches."""
    m = board.map
    if m is not None:
        return "%s (%s)" % (m.board, m.name)
    return "unknown (UIDs %s)" % " ".join("%04X" % r.uid for r in board.drivers)


def driver_name(board, uid: int) -> str:
    return board.driver_name(uid) or "?"
