"""Draw waveforms (orfa.waves.Wave) as a PNG with matplotlib: one row per
signal, the time axis counted from the window's start in a unit that suits
its length (us, ms or s), each row annotated with what orfa.waves measures
(every pulse's width when they fit, and a summary line: widths, and period
and duty for a periodic line), and a serial line or SDA with what
orfa.decode read on it (its bytes; START, address + R/W, data, ACK/NACK,
STOP) written over each frame.

matplotlib is the extra `orfa[plot]`; this module imports it only when it
draws, and says which package is missing otherwise.
"""

from __future__ import annotations

from typing import List, NamedTuple, Optional, Sequence

from . import decode, waves
from .errors import PlotUnavailable

MAX_PULSE_LABELS = 8          # a row with more complete pulses gets only its summary
MAX_MARK_LABELS = 150         # a row with more decoded frames in the window: none written
ROW_HEIGHT_IN = 0.62
WIDTH_IN = 12.0
ROWS_WIDTH_IN = 8.2           # about the width the rows get (right of the labels, left of the notes)
LABEL_CHAR_IN = 0.06          # about a character's width at a pulse label's 7.5 pt


class Row(NamedTuple):
    wave: waves.Wave
    label: str                # the y axis text: name and what the pin does
    periodic: bool = True     # False: a bus or a serial line (no period, no duty)
    frames: Sequence[decode.Frame] = ()   # what orfa.decode read on the line


def frames_in(row: Row) -> List[decode.Frame]:
    """The row's decoded frames that lie whole inside its window."""
    w = row.wave
    return [f for f in row.frames if f.start >= w.start and f.end <= w.end]


def mark_text(frame: decode.Frame) -> str:
    """What a frame says on the picture: a serial byte as the character it
    is in ORFA's text protocol (`S`, `0`, `CR`; `!` after it when its stop
    bit read low), the I2C frames as ORFA's replies spell them (`S`, `Sr`,
    `A0 W`, `41`, `A`, `N`, `P`)."""
    if frame.kind == "byte":
        return decode.char(frame.value)
    if frame.kind == "framing error":
        return decode.char(frame.value) + "!"
    return frame.text


class Axis(NamedTuple):
    origin: int               # the cycle the axis counts from (the window's start)
    unit: str                 # "us", "ms" or "s"
    us_per_unit: float
    label: str                # the axis title


def time_axis(start: int, end: int, f_cpu: int) -> Axis:
    """The time axis of a window: counted from its start, in us below 2 ms,
    ms below 2 s, else s; its title says where the window starts."""
    span = waves.us(end - start, f_cpu)
    unit, per = ("us", 1.0) if span < 2000 else ("ms", 1e3) if span < 2e6 else ("s", 1e6)
    since = "from power-up" if start == 0 else \
        "from %s after power-up" % waves.show_us(start, f_cpu)
    return Axis(start, unit, per, "time (%s) %s, simulated, %.4g MHz CPU clock"
                % ("\u00b5s" if unit == "us" else unit, _micro(since), f_cpu / 1e6))


class Annotation(NamedTuple):
    signal: str
    kind: str                 # "pulse" (one pulse's width), "decoded" (a frame) or "summary"
    text: str
    cycles: Optional[int]     # the measured width (pulse), the frame's start, or None


def annotations(rows: Sequence[Row], f_cpu: int) -> List[Annotation]:
    """What the plot writes next to each row (also what the tests check):
    a decoded line's frames (when at most MAX_MARK_LABELS), else each
    pulse's width (when at most MAX_PULSE_LABELS); then the summary."""
    out = []
    for row in rows:
        name = row.wave.name
        ps = waves.pulses(row.wave)
        frames = frames_in(row)
        if frames:
            if len(frames) <= MAX_MARK_LABELS:
                out += [Annotation(name, "decoded", mark_text(f), f.start) for f in frames]
        elif 0 < len(ps) <= MAX_PULSE_LABELS:
            for rise, fall in ps:
                out.append(Annotation(name, "pulse", waves.show_us(fall - rise, f_cpu),
                                      fall - rise))
        out.append(Annotation(name, "summary",
                              waves.describe(waves.summary(row.wave), f_cpu,
                                             periodic=row.periodic, origin=row.wave.start),
                              None))
    return out


def require() -> None:
    """PlotUnavailable (saying what to install) when matplotlib is missing."""
    _matplotlib()


def _matplotlib():
    try:
        import matplotlib
    except ImportError:
        raise PlotUnavailable("orfa plot needs matplotlib: pip install 'orfa[plot]'") from None
    matplotlib.use("Agg")                 # files only, no display needed
    import matplotlib.pyplot as plt
    return plt


def _micro(text: str) -> str:
    return text.replace(" us", " \u00b5s")


def _steps(wave: waves.Wave, f_cpu: int, axis: Axis):
    def x(cycle):
        return waves.us(cycle - axis.origin, f_cpu) / axis.us_per_unit
    xs = [x(wave.start)]
    ys = [wave.level]
    for cycle, level in wave.edges:
        xs += [x(cycle)] * 2
        ys += [ys[-1], level]
    xs.append(x(wave.end))
    ys.append(ys[-1])
    return xs, ys


#: The colour of a decoded frame's text by its kind (default: a byte's).
_FRAME_COLOURS = {"start": "tab:green", "restart": "tab:green", "stop": "tab:green",
                  "ack": "0.35", "nack": "tab:red", "partial": "tab:red",
                  "framing error": "tab:red"}
_POINT_KINDS = ("start", "restart", "stop", "ack", "nack")
#: Written under the line (the rest over it): so a START right after an ACK
#: does not cover it.
_UNDER_KINDS = ("start", "restart", "stop")
#: Drawn narrower than printed: a space of the serial line is one glyph.
GLYPHS = {"SP": "\u2423"}


#: A row whose texts would cover each other for more than this share of its
#: frames gets none (only the shading): a few words of a sentence mislead.
MAX_COVERED = 0.25


def _draw_frames(ax, frames: Sequence[decode.Frame], f_cpu: int, axis: Axis,
                 span: float) -> None:
    """Each frame's text over it (a START or STOP under it); a byte's span
    lightly shaded. A text that would cover the one before it on its level
    is left out (the printed annotations have them all); when that is more
    than MAX_COVERED of them, all are."""
    def x(cycle):
        return waves.us(cycle - axis.origin, f_cpu) / axis.us_per_unit
    right = {True: float("-inf"), False: float("-inf")}   # under: where the last text ends
    texts = []
    for f in frames:
        point = f.kind in _POINT_KINDS
        if not point:
            ax.axvspan(x(f.start), x(f.end), color="tab:purple", alpha=0.08, linewidth=0)
        text = mark_text(f)
        text = GLYPHS.get(text, text)
        # a name or hex of a serial byte (CR, 0D) is smaller than a character
        size = 6.5 if point else 6 if f.kind == "byte" and len(text) > 1 else 7
        middle = x((f.start + f.end) / 2)
        half = len(text) * LABEL_CHAR_IN * size / 7.5 * span / ROWS_WIDTH_IN / 2
        under = f.kind in _UNDER_KINDS
        if middle - half < right[under]:
            continue
        right[under] = middle + half
        texts.append((middle, under, text, size, _FRAME_COLOURS.get(f.kind, "tab:purple")))
    if len(texts) < (1 - MAX_COVERED) * len(frames):
        return
    for middle, under, text, size, colour in texts:
        ax.text(middle, -0.08 if under else 1.08, text, ha="center",
                va="top" if under else "bottom", fontsize=size, color=colour)


def render(rows: Sequence[Row], f_cpu: int, out: str, title: str = "") -> List[Annotation]:
    """Draw rows into the PNG (or SVG/PDF by out's suffix) at out; returns
    the annotations written on it."""
    plt = _matplotlib()
    notes = annotations(rows, f_cpu)
    n = max(1, len(rows))
    fig, axes = plt.subplots(n, 1, sharex=True, squeeze=False,
                             figsize=(WIDTH_IN, 1.1 + ROW_HEIGHT_IN * n))
    axes = [a[0] for a in axes]
    start, end = (rows[0].wave.start, rows[0].wave.end) if rows else (0, 1)
    axis = time_axis(start, end, f_cpu)
    span = waves.us(end - start, f_cpu) / axis.us_per_unit
    for ax, row in zip(axes, rows):
        xs, ys = _steps(row.wave, f_cpu, axis)
        ax.plot(xs, ys, color="tab:blue", linewidth=1.0)
        ax.fill_between(xs, 0, ys, color="tab:blue", alpha=0.15, linewidth=0)
        ax.set_ylim(-0.6 if row.frames else -0.25, 1.75)
        ax.set_yticks([])
        ax.set_ylabel(row.label, rotation=0, ha="right", va="center", fontsize=9)
        for side in ("top", "right", "left"):
            ax.spines[side].set_visible(False)
        ax.grid(axis="x", color="0.85", linewidth=0.6)
        mine = [a for a in notes if a.signal == row.wave.name]
        pulses = waves.pulses(row.wave)
        right = float("-inf")               # where the last width written ends
        for (rise, fall), note in zip(pulses, [a for a in mine if a.kind == "pulse"]):
            middle = waves.us((rise + fall) / 2 - axis.origin, f_cpu) / axis.us_per_unit
            half = len(note.text) * LABEL_CHAR_IN * span / ROWS_WIDTH_IN / 2
            if middle - half < right:
                continue                     # it would be written over the one before
            right = middle + half
            ax.annotate(_micro(note.text), xy=(middle, 1.05),
                        ha="center", va="bottom", fontsize=7.5, color="tab:red")
        if any(a.kind == "decoded" for a in mine):
            _draw_frames(ax, frames_in(row), f_cpu, axis, span)
        summary = [a.text for a in mine if a.kind == "summary"]
        ax.text(1.01, 0.35, _micro(summary[0]).replace(", ", "\n", 1) if summary else "",
                transform=ax.transAxes, ha="left", va="center", fontsize=8, color="0.2")
    axes[-1].set_xlim(0, span)
    axes[-1].ticklabel_format(axis="x", useOffset=False, style="plain")
    axes[-1].set_xlabel(axis.label)
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.subplots_adjust(right=0.76)        # the measurements, right of the rows
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return notes
