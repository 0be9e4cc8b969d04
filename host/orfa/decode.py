"""Decode a serial line and an I2C bus from their waveforms (orfa.waves.Wave,
times in CPU cycles), as a logic analyzer's protocol decoders do: what
`orfa plot` writes on the rows of a serial line and of SDA (docs/plot.md).
Pure functions, no plotting.

    decode.uart(wave, bit_cycles)   # [Frame(start, end, "byte", 0x53, "53")]
    decode.i2c(sda, scl)            # START, address + R/W, data, ACK/NACK, STOP
"""

from __future__ import annotations

from bisect import bisect_right
from typing import List, NamedTuple, Optional, Sequence, Tuple

from .waves import Wave


class Frame(NamedTuple):
    """One decoded thing on the wire, start..end in cycles (equal for a
    START or a STOP, which happen at one edge)."""
    start: int
    end: int
    kind: str                 # uart: "byte", "framing error"; i2c: "start",
    #                           "restart", "address", "data", "ack", "nack",
    #                           "stop", "partial" (a byte cut by START/STOP)
    value: Optional[int]      # the byte (the address byte as on the wire, R/W in
    #                           bit 0), a partial byte's bit count; else None
    text: str                 # short, as written on a plot: 53, A1 R, S, Sr, A, N, P


# --- the serial line ---------------------------------------------------------

def _level_at(wave: Wave):
    """A function: the wave's level at a cycle (after the edges at it)."""
    cycles = [c for c, _ in wave.edges]

    def level(t: float) -> int:
        i = bisect_right(cycles, t)
        return wave.edges[i - 1][1] if i else wave.level
    return level


def uart(wave: Wave, bit: float) -> List[Frame]:
    """The 8N1 frames on a line that idles high, at BIT cycles a bit
    (F_CPU / baud: 64 at 115200 and 7.3728 MHz). A frame begins at a falling
    edge whose bit still reads low half a bit later (else a glitch: the next
    falling edge is tried); each bit is read at its middle, LSB first; a stop
    bit that reads low makes a "framing error" (its byte as read). The next
    frame is looked for from the stop bit's middle on, as a UART's receiver
    does. A frame whose stop bit would end past the wave's window is left out."""
    if bit <= 0:
        raise ValueError("a bit time must be positive, not %r" % (bit,))
    level = _level_at(wave)
    out: List[Frame] = []
    ready = float(wave.start)
    for cycle, lv in wave.edges:
        if lv or cycle < ready:
            continue
        if cycle + 10 * bit > wave.end:
            break
        if level(cycle + bit / 2):
            continue                          # a glitch, not a start bit
        value = sum(level(cycle + (1.5 + i) * bit) << i for i in range(8))
        stop = level(cycle + 9.5 * bit)
        out.append(Frame(cycle, cycle + int(round(10 * bit)),
                         "byte" if stop else "framing error", value, "%02X" % value))
        ready = cycle + 9.5 * bit
    return out


def char(value: int) -> str:
    """A byte of ORFA's text protocol as a person reads it: the character
    when printable, CR, LF, SP, else its hex."""
    names = {0x0D: "CR", 0x0A: "LF", 0x20: "SP"}
    if value in names:
        return names[value]
    return chr(value) if 0x20 < value < 0x7F else "%02X" % value


# --- the I2C bus -------------------------------------------------------------

# At one cycle, SCL falling is taken first and SCL rising last: a bit's SDA
# changes while SCL is low, and SCL rising samples the SDA of its cycle.
_SCL_FALL, _SDA, _SCL_RISE = 0, 1, 2


def _merged(sda: Wave, scl: Wave) -> List[Tuple[int, int, int]]:
    events = [(c, _SDA, lv) for c, lv in sda.edges]
    events += [(c, _SCL_RISE if lv else _SCL_FALL, lv) for c, lv in scl.edges]
    return sorted(events)


def i2c(sda: Wave, scl: Wave) -> List[Frame]:
    """What the bus carried: START (SDA falls while SCL is high), repeated
    START ("restart", a START before the STOP), STOP (SDA rises while SCL is
    high), and between them bytes of 8 bits, each read as SCL rises, MSB
    first, with the 9th bit the receiver's ACK (SDA low) or NACK. The first
    byte after a START is the address (the byte as on the wire, R/W in bit
    0: `A0 W`, `A1 R`, as ORFA's requests write it), the others data. A
    byte runs from its first bit's rising SCL to its 8th bit's falling SCL,
    however long a slave holds SCL low in between (clock stretching). A
    START or STOP in the middle of a byte ends it as a "partial" frame (its
    bit count in value). Nothing is read before the first START."""
    out: List[Frame] = []
    sda_level, scl_level = sda.level, scl.level
    busy = False
    bits: List[Tuple[int, int]] = []          # (rising SCL, SDA) of the byte so far
    high: Optional[Tuple[int, int]] = None    # SCL is high: since when, SDA then
    first = True                              # the next byte is an address

    def cut(cycle: int) -> None:
        if bits and len(bits) != 8:           # 8: its byte is out, its ACK cut
            out.append(Frame(bits[0][0], cycle, "partial", len(bits), "%d bits" % len(bits)))
        bits.clear()

    for cycle, what, lv in _merged(sda, scl):
        if what == _SDA:
            if lv != sda_level and scl_level:
                # SDA moving while SCL is high: no bit, a START or a STOP
                high = None
                if lv == 0:
                    cut(cycle)
                    out.append(Frame(cycle, cycle, "restart" if busy else "start", None,
                                     "Sr" if busy else "S"))
                    busy, first = True, True
                elif busy:
                    cut(cycle)
                    out.append(Frame(cycle, cycle, "stop", None, "P"))
                    busy = False
            sda_level = lv
            continue
        if what == _SCL_RISE and not scl_level:
            high = (cycle, sda_level)
        elif what == _SCL_FALL and scl_level:
            if busy and high is not None:
                bits.append(high)             # a bit: SCL high and low again, SDA steady
                if len(bits) == 8:
                    value = 0
                    for _, b in bits:
                        value = value << 1 | b
                    if first:
                        text = "%02X %s" % (value, "R" if value & 1 else "W")
                        out.append(Frame(bits[0][0], cycle, "address", value, text))
                    else:
                        out.append(Frame(bits[0][0], cycle, "data", value, "%02X" % value))
                    first = False
                elif len(bits) == 9:
                    ack = bits[8][1] == 0
                    out.append(Frame(bits[8][0], cycle, "ack" if ack else "nack", None,
                                     "A" if ack else "N"))
                    bits.clear()
            high = None
        scl_level = lv
    return out


def bytes_of(frames: Sequence[Frame], kinds: Sequence[str] = ("byte",)) -> bytes:
    """The values of the frames of KINDS, in order."""
    return bytes(f.value for f in frames if f.kind in kinds)

