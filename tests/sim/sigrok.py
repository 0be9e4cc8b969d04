"""Debian's sigrok-cli on the simulator's VCD (docs/simulator.md, "VCD"):
run one of sigrok's own protocol decoders on a capture and take its
annotations back in CPU cycles. The tests that compare what sigrok decodes
with what the host sent and received use this (test_sigrok_*.py,
test_capture_doc.py, test_bus_faults_midbyte.py)."""

import json
import re
import shutil
import subprocess
import time

import pytest

from orfa.protocol import F_CPU

#: The VCD's timescale at 7.3728 MHz, and so sigrok's sample rate (10 MHz).
TIMESCALE, UNIT_S = "100ns", 1e-7

needs_sigrok = pytest.mark.skipif(shutil.which("sigrok-cli") is None,
                                  reason="needs sigrok-cli (tools/setup.sh installs it)")


def sample_cycle(sample):
    """A sample of the capture (one timescale unit) as the nearest cycle:
    the simulator wrote each edge at its cycle's time rounded to the unit."""
    return (2 * sample * F_CPU + 10 ** 7) // (2 * 10 ** 7)


def decode(path, decoder, annotations):
    """sigrok-cli's DECODER (`uart:rx=D0:...`) on the capture at PATH, its
    ANNOTATIONS (`uart=rx-data:tx-data`) as {row: [(begin cycle, end cycle,
    text)]} (row: sigrok's name, "RX", "MOSI transfer"), and the seconds it
    took."""
    cmd = ["sigrok-cli", "-i", str(path), "-I", "vcd", "-P", decoder, "-A", annotations,
           "--protocol-decoder-jsontrace"]
    t0 = time.monotonic()
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    took = time.monotonic() - t0
    assert r.returncode == 0, r.stderr
    out, begun = {}, {}
    for ev in json.loads(r.stdout)["traceEvents"]:
        # "ts": microseconds, 0.1 a sample; each annotation a B and its E
        cycle = sample_cycle(round(ev["ts"] * 1e-6 / UNIT_S))
        if ev["ph"] == "B":
            begun[ev["tid"]] = cycle
        elif ev["ph"] == "E":
            out.setdefault(ev["tid"], []).append((begun.pop(ev["tid"]), cycle, ev["name"]))
    return out, took


def lines(path, decoder, annotations):
    """sigrok-cli's plain output of DECODER's ANNOTATIONS on the capture at
    PATH (`uart-1: 53`), as a shell prints it, trailing blanks off."""
    r = subprocess.run(["sigrok-cli", "-i", str(path), "-I", "vcd", "-P", decoder,
                        "-A", annotations], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return [line.rstrip() for line in r.stdout.splitlines()]


_I2C_CONDITIONS = {"Start": "S", "Start repeat": "Sr", "Stop": "P"}


def i2c_view(path):
    """sigrok's i2c decoder on the capture's wires `scl` and `sda`, in the
    order its annotations begin: "S", "Sr" and "P" for START, repeated START
    and STOP, (kind, value, ack) for every byte: kind "AW"/"AR" with the
    7-bit address, "DW"/"DR" with the data byte; ack 1 for ACK, 0 for
    NACK."""
    rows, _ = decode(path, "i2c:scl=scl:sda=sda",
                     "i2c=start:repeat-start:stop:ack:nack:address-read:address-write:"
                     "data-read:data-write")
    out = []
    for _, _, name in sorted((a for row in rows.values() for a in row), key=lambda a: a[0]):
        if name in ("Write", "Read"):
            continue                    # the R/W bit: the address's annotation says it
        if name in _I2C_CONDITIONS:
            out.append(_I2C_CONDITIONS[name])
        elif name in ("ACK", "NACK"):
            kind, value, _ = out[-1]
            out[-1] = (kind, value, int(name == "ACK"))
        else:
            m = re.fullmatch(r"(Address|Data) (write|read): ([0-9A-F]{2})", name)
            assert m, name
            kind = ("A" if m.group(1) == "Address" else "D") + m.group(2)[0].upper()
            out.append((kind, int(m.group(3), 16), None))
    return out


#: sigrok's i2c annotations (its addr-data row) as orfa.decode's texts,
#: ORFA's letters; its "Write"/"Read" (the R/W bit alone) has none.
_I2C_TEXTS = [("Start repeat", "Sr"), ("Start", "S"), ("Stop", "P"), ("NACK", "N"),
              ("ACK", "A"), ("Address write: ", "{} W"), ("Address read: ", "{} R"),
              ("Data write: ", "{}"), ("Data read: ", "{}")]


def i2c_texts(lines):
    """sigrok-cli's plain i2c output (`i2c-1: Address write: A0`, with
    address_format=unshifted) as orfa.decode writes it (`A0 W`)."""
    out = []
    for line in lines:
        text = line.split(": ", 1)[1] if ": " in line else ""
        for prefix, form in _I2C_TEXTS:
            if text.startswith(prefix):
                out.append(form.format(text[len(prefix):]))
                break
    return out
