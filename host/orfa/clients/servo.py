"""board.servo: the servo driver's SP (widths) and RS (pulsing mask)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import List, Mapping, Optional, Set

from ..protocol import OrfaError

#: Widths read back per request: 28 channels keep a slave's reply (with its
#: status read) within 127 characters.
READ_CHANNELS = 28


@dataclass(frozen=True)
class ServoRange:
    """A servo's documented travel: min_us gives min_deg, max_us max_deg
    (the manual: +-75 degrees at 1000/2000 us, so 1200 us is -45)."""

    min_us: int = 1000
    max_us: int = 2000
    min_deg: float = -75.0
    max_deg: float = 75.0

    def __post_init__(self):
        if self.min_us == self.max_us or self.min_deg == self.max_deg:
            raise ValueError("a servo range needs two different widths and angles")

    def degrees(self, us: int) -> float:
        """deg = min_deg + (max_deg - min_deg) * (us - min_us) / (max_us - min_us)."""
        return self.min_deg + (self.max_deg - self.min_deg) * (us - self.min_us) \
            / (self.max_us - self.min_us)

    def width(self, degrees: float) -> int:
        """The width for an angle, rounded to whole us; ValueError outside the range."""
        lo, hi = sorted((self.min_deg, self.max_deg))
        if not lo <= degrees <= hi:
            raise ValueError("%g degrees is outside the servo's %g..%g" % (degrees, lo, hi))
        return round(self.min_us + (self.max_us - self.min_us) * (degrees - self.min_deg)
                     / (self.max_deg - self.min_deg))


class Servo:
    def __init__(self, board):
        self.board = board
        m = board.board_map("servo")
        #: channels of the board's servo driver: 16 on an M32-D, 32 on an M128-S
        self.channels: int = m.servo_channels
        #: SP takes at most this many [channel][hi][lo] triples per write
        self.max_triples: int = m.limits["servo_triples"]

    def _ch(self, ch: int) -> int:
        if not isinstance(ch, int) or isinstance(ch, bool) or not 0 <= ch < self.channels:
            raise ValueError("servo channel %r: channels are 0..%d" % (ch, self.channels - 1))
        return ch

    def width(self, ch: int) -> int:
        """Channel ch's width in us (0: off)."""
        return self.widths(ch, 1)[0]

    def widths(self, first: int = 0, count: Optional[int] = None) -> List[int]:
        """Widths of `count` channels from `first` (default: to the last);
        SP's first channel selected by a 1-byte write, then read, 28
        channels per request, requests pipelined."""
        self._ch(first)
        if count is None:
            count = self.channels - first
        if not isinstance(count, int) or count < 1 or first + count > self.channels:
            raise ValueError("%r channels from %d: the board has %d" % (count, first, self.channels))
        b = self.board
        items = [[b.op_read("servo", "SP", 2 * min(READ_CHANNELS, first + count - ch), [ch])]
                 for ch in range(first, first + count, READ_CHANNELS)]
        data = b"".join(reads[0] for reads in b.execute(items))
        return [data[i] << 8 | data[i + 1] for i in range(0, len(data), 2)]

    def set_width(self, ch: int, us: int) -> None:
        """Channel ch to us microseconds (0: off; the board clamps others to 500..2500)."""
        self.set_widths({ch: us})

    def set_widths(self, widths: Mapping[int, int]) -> None:
        """Several channels, {ch: us}: SP writes of at most 16 triples,
        pipelined; the channels of one write start together."""
        triples = []
        for ch, us in sorted(dict(widths).items()):
            self._ch(ch)
            if not isinstance(us, int) or isinstance(us, bool) or not 0 <= us <= 0xFFFF:
                raise ValueError("servo width must be 0..65535 us, not %r" % (us,))
            triples.append(bytes([ch, us >> 8, us & 0xFF]))
        if not triples:
            return
        b = self.board
        n = self.max_triples
        b.execute([[b.op_write("servo", "SP", b"".join(triples[i:i + n]))]
                   for i in range(0, len(triples), n)])

    def off(self, ch: Optional[int] = None) -> None:
        """Stop pulsing channel ch, or every channel."""
        chans = range(self.channels) if ch is None else [self._ch(ch)]
        self.set_widths({c: 0 for c in chans})

    def pulsing(self) -> Set[int]:
        """The channels that pulse now (RS, highest channel first on the wire)."""
        data = self.board.read("servo", "RS", (self.channels + 7) // 8)
        mask = int.from_bytes(data, "big")
        return {ch for ch in range(self.channels) if mask >> ch & 1}

    def set_angle(self, ch: int, degrees: float, range: ServoRange = ServoRange()) -> None:
        """Channel ch to an angle of the servo's range (the manual's formula)."""
        self.set_width(ch, range.width(degrees))

    def angle(self, ch: int, range: ServoRange = ServoRange()) -> float:
        """Channel ch's angle from its width; OrfaError if it is off."""
        us = self.width(ch)
        if us == 0:
            raise OrfaError("servo channel %d is off (width 0): no angle" % ch)
        return range.degrees(us)
