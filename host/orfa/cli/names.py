"""Names for what introspection reports: the board, each driver."""

from __future__ import annotations

from typing import Sequence

from .. import boards


def board_of(records: Sequence) -> str:
    """The board whose drivers these are: "m32d" or "unknown (UIDs ...)"."""
    uids = tuple(r.uid for r in records)
    for name, known in boards.BOARD_UIDS.items():
        if uids == known:
            return name
    return "unknown (UIDs %s)" % " ".join("%04X" % u for u in uids)


def driver_name(uid: int) -> str:
    return boards.DRIVER_NAMES.get(uid, "?")
