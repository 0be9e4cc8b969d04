"""Read the simulator's VCD (`orfa sim --vcd FILE`, docs/simulator.md "VCD").

The file holds 1-bit wires, one scope per board (`board`, `board_10` for
the slave at 0x10, whose names carry the prefix: `10/servo3`) with a comment
that names the board (`board m32d OR-AVR-M32-D`), a timescale no longer
than one cycle (100 ns at 7.3728 MHz; older files 1 ps) and the CPU clock
in its first comment. Times come back as CPU cycles: the simulator rounds
each cycle's time to the nearest unit, at most half a unit and so less than
half a cycle off, so rounding back gives the exact cycle (integer
arithmetic, exact however long the file).

    trace = vcd.load("board.vcd")
    trace.f_cpu, trace.names(), trace.edges("servo3")   # [(cycle, level), ...]
"""

from __future__ import annotations

import re
from typing import Dict, Iterable, Iterator, List, Optional, Tuple

from .errors import VcdError

Edge = Tuple[int, int]                   # (cycle, level)

_CLOCK = re.compile(r"(\d+(?:\.\d+)?)\s*Hz")
_UNITS_FS = {"s": 10 ** 15, "ms": 10 ** 12, "us": 10 ** 9, "ns": 10 ** 6, "ps": 10 ** 3, "fs": 1}
_FS_PER_S = 10 ** 15


class Trace:
    """The waveforms of one VCD: per signal its level at cycle 0 and its
    edges (a change of level), oldest first."""

    def __init__(self, f_cpu: int, scopes: Dict[str, List[str]],
                 initial: Dict[str, int], changes: Dict[str, List[Edge]], end: int,
                 boards: Optional[Dict[str, str]] = None):
        self.f_cpu = f_cpu
        self.scopes = scopes                 # scope -> signal names, file order
        self.initial = initial
        self.changes = changes
        self.end = end                       # the last time in the file (cycles)
        self.boards = boards or {}           # scope -> board name ("m32d")

    def board_of(self) -> Dict[str, str]:
        """Signal prefix ("" the gateway, "10" a slave) -> board name."""
        out = {}
        for scope, board in self.boards.items():
            names = self.scopes.get(scope) or [""]
            out[names[0].rpartition("/")[0]] = board
        return out

    def names(self) -> List[str]:
        return [name for names in self.scopes.values() for name in names]

    def edges(self, name: str) -> List[Edge]:
        return self.changes[name]


def _tokens(lines: Iterable[str]) -> Iterator[Tuple[int, str]]:
    for number, line in enumerate(lines, 1):
        for tok in line.split():
            yield number, tok


def _cycles(t: int, fs_per_unit: int, f_cpu: int) -> int:
    """Time T in units of FS_PER_UNIT femtoseconds as the nearest cycle."""
    return (2 * t * fs_per_unit * f_cpu + _FS_PER_S) // (2 * _FS_PER_S)


def parse(text: str, where: str = "VCD") -> Trace:
    """A Trace from the text of a VCD file; VcdError names the line at fault."""
    tokens = _tokens(text.splitlines())
    f_cpu: Optional[int] = None
    fs_per_unit: Optional[int] = None
    scopes: Dict[str, List[str]] = {}
    boards: Dict[str, str] = {}              # scope -> board ("m32d"), as its comment says
    ids: Dict[str, List[str]] = {}           # id code -> names (one wire may have several)
    scope: List[str] = []
    line = 0

    def block(first_line: int) -> List[str]:
        words = []
        for ln, tok in tokens:
            if tok == "$end":
                return words
            words.append(tok)
        raise VcdError("%s:%d: a declaration without $end" % (where, first_line))

    for line, tok in tokens:
        if tok == "$enddefinitions":
            block(line)
            break
        if tok == "$comment":
            words = block(line)
            m = _CLOCK.search(" ".join(words))
            if m and f_cpu is None:
                f_cpu = int(round(float(m.group(1))))
            if scope and len(words) >= 2 and words[0] == "board":
                boards[scope[-1]] = words[1]
        elif tok == "$timescale":
            words = "".join(block(line))
            m = re.fullmatch(r"(1|10|100)(s|ms|us|ns|ps|fs)", words)
            if not m:
                raise VcdError("%s:%d: timescale %r" % (where, line, words))
            fs_per_unit = int(m.group(1)) * _UNITS_FS[m.group(2)]
        elif tok == "$scope":
            words = block(line)
            scope.append(words[-1] if words else "?")
            scopes.setdefault(scope[-1], [])
        elif tok == "$upscope":
            block(line)
            if scope:
                scope.pop()
        elif tok == "$var":
            words = block(line)
            if len(words) < 4:
                raise VcdError("%s:%d: $var needs type, size, id and name" % (where, line))
            if words[1] != "1":
                continue                     # the simulator writes only 1-bit wires
            name = words[3]
            scopes.setdefault(scope[-1] if scope else "", []).append(name)
            ids.setdefault(words[2], []).append(name)
        elif tok.startswith("$"):
            block(line)
    else:
        raise VcdError("%s: no $enddefinitions: not a VCD" % where)
    if not f_cpu:
        raise VcdError("%s: no CPU clock in its comment: not the simulator's VCD" % where)
    if fs_per_unit is None:
        raise VcdError("%s: no $timescale" % where)

    names = [n for ns in scopes.values() for n in ns]
    initial = {n: 0 for n in names}
    changes: Dict[str, List[Edge]] = {n: [] for n in names}
    level = dict(initial)
    now = 0
    dumping_initial = True
    for line, tok in tokens:
        first = tok[0]
        if first == "#":
            try:
                now = _cycles(int(tok[1:]), fs_per_unit, f_cpu)
            except ValueError:
                raise VcdError("%s:%d: time %r" % (where, line, tok)) from None
            if now > 0:
                dumping_initial = False
        elif first in "01xXzZ":
            code = tok[1:]
            if code not in ids:
                raise VcdError("%s:%d: unknown id %r" % (where, line, code))
            value = 1 if first == "1" else 0
            for name in ids[code]:
                if dumping_initial and not changes[name]:
                    initial[name] = level[name] = value
                elif value != level[name]:
                    changes[name].append((now, value))
                    level[name] = value
        elif tok in ("$dumpvars", "$dumpall", "$dumpon", "$dumpoff", "$end"):
            continue
        elif first in "bBrR":
            next(tokens, None)               # a vector value and its id: not ours
        else:
            raise VcdError("%s:%d: unexpected %r" % (where, line, tok))
    return Trace(f_cpu, scopes, initial, changes, now, boards)


def load(path: str) -> Trace:
    with open(path, encoding="ascii", errors="replace") as f:
        return parse(f.read(), where=str(path))
