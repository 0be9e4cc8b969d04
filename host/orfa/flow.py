"""Pipelining rules, pure: how many requests may be in flight, and which
reply lines could answer a request (anything else is noise).

The flow rule of docs/protocol.md ("Flow"): the firmware's receive buffer holds
at least 256 characters, so a host keeps fewer than 256 characters of requests (each with
its terminator) unanswered. The gateway answers every request with exactly
one line, in order.
"""

from __future__ import annotations

import re
from typing import Optional, Pattern

#: Characters of unanswered requests (terminators included) stay below this.
FLOW_WINDOW = 256

#: The resynchronisation marker: a request whose reply is known exactly.
MARKER = "V"
MARKER_REPLY = "V1.1"
#: The request after the marker in the opening sync (Gateway.sync_open): the
#: clock, a read that changes nothing and whose reply is not `V1.1`.
SYNC_SECOND = "C"
SYNC_SECOND_REPLY = re.compile(r"C[0-9A-F]{4}\Z")

_ERROR = r"ERROR [0-9A-F]{2}"
_HEX = re.compile(r"[0-9A-F]*\Z")


def request_cost(line: str) -> int:
    """Characters a request holds in the firmware's receive buffer."""
    return len(line) + 1


def _transaction_reply(body: str) -> Optional[str]:
    """The reply regex of an `S...P` request (spaces removed, upper case),
    or None if the request cannot parse (then only ERROR can answer)."""
    if not body.endswith("P"):
        return None
    parts = []
    for frame in body[:-1].split("S")[1:]:
        if len(frame) < 2 or len(frame) % 2 or not _HEX.match(frame):
            return None
        addr = int(frame[:2], 16)
        data = frame[2:]
        if addr & 1:
            if len(data) != 2 or int(data, 16) == 0:
                return None
            parts.append("SR[0-9A-F]{%d}" % (2 * int(data, 16)))
        else:
            parts.append("SW" + "A" * (len(data) // 2))
    if not parts or body[0] != "S":
        return None
    return "".join(parts) + "P"


def reply_pattern(line: str) -> Optional[Pattern[str]]:
    """A regex every possible reply to request `line` matches (ERROR
    replies included); None for a line that gets no reply (empty, or a
    comment)."""
    text = line.strip(" ")
    if not text:
        return None
    if text.startswith("#"):
        return None
    body = text.replace(" ", "").upper()
    cmd = body[0]
    if cmd == "V":
        good = r"V\d+\.\d+"
    elif cmd == "X":
        good = "X"
    elif cmd == "L":
        good = "L[0-9A-F]{2}"
    elif cmd == "C":
        good = "C[0-9A-F]{4}"
    elif cmd == "S":
        good = _transaction_reply(body)
    else:
        good = None
    return re.compile("(?:%s)\\Z" % (_ERROR if good is None else good + "|" + _ERROR))


def plausible(pattern: Pattern[str], reply: str) -> bool:
    """True if `reply` (text without CR LF) could answer the request."""
    return pattern.match(reply) is not None
