"""Measure a 1-bit waveform: its pulses, period and duty, in CPU cycles.

A Wave is a signal's level at the start of a window and its edges inside it
(cycle, new level). Pure functions, no plotting: `orfa plot` annotates what
these measure, and the tests check them against the simulator's `measure`.
"""

from __future__ import annotations

from typing import List, NamedTuple, Optional, Sequence, Tuple

Edge = Tuple[int, int]


class Wave(NamedTuple):
    name: str
    start: int                      # first cycle of the window
    end: int                        # the cycle after the window
    level: int                      # the level at `start`
    edges: Tuple[Edge, ...]         # changes of level, start <= cycle < end, oldest first


class Summary(NamedTuple):
    pulses: int                     # complete pulses in the window (see polarity)
    width_min: Optional[int]        # their widths (cycles)
    width_max: Optional[int]
    period: Optional[int]           # mean rising-to-rising period (cycles), if two rises
    duty: Optional[float]           # high time / time over the complete periods
    level: int                      # the level at the end of the window
    polarity: int                   # 1: high pulses, 0: low ones (idles high)
    last_edge: Optional[Edge]       # the window's last edge (cycle, level), if any


def window(name: str, initial: int, edges: Sequence[Edge], start: int, end: int) -> Wave:
    """The Wave of a signal between start and end, from its level before its
    first edge (`initial`) and its edges (a repeated level is not an edge)."""
    level = initial
    at_start = None
    inside: List[Edge] = []
    for cycle, lv in edges:
        if cycle >= end:
            break
        if cycle >= start and at_start is None:
            at_start = level
        if lv == level:
            continue
        if cycle >= start:
            inside.append((cycle, lv))
        level = lv
    if at_start is None:
        at_start = level
    return Wave(name, start, end, at_start, tuple(inside))


def clip(wave: Wave, start: int, end: int) -> Wave:
    """The part of a wave between start and end (within its own window)."""
    return window(wave.name, wave.level, wave.edges, max(start, wave.start),
                  min(end, wave.end))


def high_time(wave: Wave) -> int:
    """Cycles the wave is high inside its window."""
    total, level, since = 0, wave.level, wave.start
    for cycle, lv in wave.edges:
        if level:
            total += cycle - since
        level, since = lv, cycle
    return total + (wave.end - since if level else 0)


def polarity(wave: Wave) -> int:
    """The level of this signal's pulses: the one it spends less time at
    (0 for a chip select or a UART line, which idle high; 1 for a servo)."""
    return 0 if 2 * high_time(wave) > wave.end - wave.start else 1


def pulses(wave: Wave, level: Optional[int] = None) -> List[Tuple[int, int]]:
    """The complete pulses (begin, end) at `level` (default: the wave's
    polarity) inside the window."""
    if level is None:
        level = polarity(wave)
    out = []
    begin = None
    for cycle, lv in wave.edges:
        if lv == level:
            begin = cycle
        elif begin is not None:
            out.append((begin, cycle))
            begin = None
    return out


def summary(wave: Wave) -> Summary:
    pol = polarity(wave)
    widths = [end - begin for begin, end in pulses(wave, pol)]
    if not widths and pulses(wave, pol ^ 1):
        pol ^= 1                    # the only whole pulse is the long one
        widths = [end - begin for begin, end in pulses(wave, pol)]
    rises = [c for c, lv in wave.edges if lv == 1]
    period = duty = None
    if len(rises) >= 2:
        span = rises[-1] - rises[0]
        period = int(round(span / (len(rises) - 1)))
        high = sum(fall - rise for rise, fall in pulses(wave, 1) if rise < rises[-1])
        duty = high / span if span else None
    level = wave.edges[-1][1] if wave.edges else wave.level
    return Summary(len(widths), min(widths) if widths else None,
                   max(widths) if widths else None, period, duty, level, pol,
                   wave.edges[-1] if wave.edges else None)


def us(cycles: float, f_cpu: int) -> float:
    """Cycles as microseconds."""
    return cycles * 1e6 / f_cpu


def show_us(cycles: float, f_cpu: int) -> str:
    """A duration for a person: 1500.0 us, 20.00 ms, 0.54 us, 12.50 s."""
    t = us(cycles, f_cpu)
    if t >= 10000000:
        return "%.2f s" % (t / 1000000)
    if t >= 10000:
        return "%.2f ms" % (t / 1000)
    if t >= 100:
        return "%.1f us" % t
    return "%.2f us" % t


def describe(s: Summary, f_cpu: int, periodic: bool = True, origin: int = 0) -> str:
    """One line: the measured widths, period (or frequency) and duty. A line
    that is not periodic (a bus, a serial line, a chip select: its pulses
    come when there is something to send) gets its widths and how many
    pulses, no period or duty. A time ("rises at") counts from `origin`
    (the cycle a plot's axis starts at)."""
    if s.pulses == 0 and (s.period is None or not periodic):
        if s.last_edge is None:
            return "steady %d" % s.level
        # one edge, or a pulse that the window cuts: when it last changed
        cycle, level = s.last_edge
        return "%s at %s" % ("rises" if level else "falls", show_us(cycle - origin, f_cpu))
    parts = []
    kind = "high" if s.polarity else "low"
    if s.width_min is not None:
        if s.width_min == s.width_max:
            parts.append("%s %s" % (kind, show_us(s.width_min, f_cpu)))
        else:
            parts.append("%s %s-%s" % (kind, show_us(s.width_min, f_cpu),
                                       show_us(s.width_max, f_cpu)))
    if not periodic:
        parts.append("%d pulse%s" % (s.pulses, "" if s.pulses == 1 else "s"))
        return ", ".join(parts)
    if s.period:
        parts.append("period %s (%s)" % (show_us(s.period, f_cpu), show_hz(f_cpu / s.period)))
    if s.duty is not None:
        parts.append("duty %.1f%%" % (100 * s.duty))
    return ", ".join(parts)


def show_hz(hz: float) -> str:
    if hz >= 1000:
        return "%.1f kHz" % (hz / 1000)
    return "%.1f Hz" % hz
