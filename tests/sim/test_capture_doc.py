"""The capture of docs/simulator.md's "In PulseView" section, made for real:
a gateway with an SPI EEPROM on C2 and an I2C EEPROM at A0 serves the
requests below, with --vcd. sigrok-cli's own decoders on the capture give
exactly the lines the doc quotes (and the bytes the host sent and read),
and `orfa plot` draws the last three requests with their decoded bytes:
the doc's picture (saved to $ORFA_SHOTS, build/shots; `make doc-images`
puts it in docs/img). PulseView is a GUI the machines here do not have, so
the doc says which tool drew the picture."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import serial

from conftest import REPLY_TIMEOUT, require_builds
from orfa import vcd
from orfa.protocol import F_CPU
from orfa.sim import SimBoard
from sigrok import i2c_texts, lines as sigrok_lines, needs_sigrok

pytestmark = needs_sigrok
pytest.importorskip("matplotlib")

ROOT = Path(__file__).resolve().parents[2]
SHOTS = Path(os.environ.get("ORFA_SHOTS", str(ROOT / "build" / "shots")))
DOC = ROOT / "docs" / "simulator.md"
WIP = 40000                        # the SPI EEPROM's 5 ms write cycle, and some
#: The M32-D gateway's SPI driver: DATA 0A, CONFIG 0B (docs/registers.md).
#: Bind channel 0 to C2 (port index 2, line 2), the bus at F_CPU/128 (57.6
#: kHz, so a byte is as long as a serial one), write enable, write A5 3C at
#: 10; after the write cycle, read them back, fetch what came back, and read
#: two bytes of the I2C EEPROM: those three are pictured.
SETUP = ["S AA 0B 00 02 02 P", "S AA 0B FF 00 06 P", "S AA 0A 00 06 P",
         "S AA 0A 00 02 10 A5 3C P"]
PICTURED = ["S AA 0A 00 03 10 00 00 P", "S AA 0A S AB 04 P", "S A0 00 S A1 02 P"]
REPLIES = ["SWAAAAP", "SWAAAAP", "SWAAAP", "SWAAAAAAP",
           "SWAAAAAAP", "SWASRFFFFA53CP", "SWASRFFFFP"]
UART = "uart:rx=D0:tx=D1:baudrate=115200"
SPI = "spi:clk=B7:mosi=B5:miso=B6:cs=C2"
I2C = "i2c:scl=scl:sda=sda:address_format=unshifted"


def capture():
    """Run the requests; the stopped sim (its directory kept), what the host
    sent and read, and the cycle the pictured requests begin."""
    require_builds(["m32d"])
    sim = SimBoard("m32d", spi=["eeprom25@C2"], eeproms=(0xA0,), control=True, vcd=True,
                   trace=True).start()
    sent, got = b"", b""
    try:
        with serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
            for req in SETUP:
                port.write(req.encode() + b"\n")
                got += port.readline()
            sim.control.wait(WIP)
            mark = sim.trace_mark()
            batch = b"".join(r.encode() + b"\n" for r in PICTURED)
            port.write(batch)                  # one after the other on the wire
            for _ in PICTURED:
                got += port.readline()
            sent = b"".join(r.encode() + b"\n" for r in SETUP) + batch
        sim.control.wait(3000)
        first = sim.trace_events(mark, kinds=["uart rx"])[0].cycle - 640
    except BaseException:
        sim.stop()
        raise
    sim.stop(keep_dir=True)
    return sim, sent, got, first


@pytest.fixture(scope="module")
def captured():
    sim, sent, got, first = capture()
    yield sim, sent, got, first
    shutil.rmtree(sim.dir, ignore_errors=True)


def plot(path, start, end, signals, out):
    """`orfa plot -v` of the capture between cycles START and END: its
    lines {row: [texts]}."""
    trace_us = 1e6 / F_CPU
    r = subprocess.run(
        [sys.executable, "-m", "orfa", "plot", str(path), "--signals"] + signals
        + ["--from", "%.1f" % (start * trace_us), "--to", "%.1f" % (end * trace_us),
           "-v", "-o", str(out)],
        env=dict(os.environ, PYTHONPATH=str(ROOT / "host")), capture_output=True,
        text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    rows = {}
    for line in r.stdout.splitlines():
        rows.setdefault(line[:10].strip(), []).append(line[11:])
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    return rows


def quoted(lines):
    """Whether docs/simulator.md has LINES one after the other in a block."""
    doc = [line[4:].rstrip() if line.startswith("    ") else None
           for line in DOC.read_text().splitlines()]
    n = len(lines)
    return any(doc[i:i + n] == lines for i in range(len(doc) - n + 1))


def as_text(lines):
    """`uart-1: 53` lines as the text they carry (the doc's `| cut -d' '
    -f2 | xxd -r -p`)."""
    return bytes(int(line.split()[1], 16) for line in lines).decode().splitlines()


def test_the_docs_capture_decodes_as_quoted_and_is_drawn(captured):
    sim, sent, got, first = captured
    path = sim.vcd_path
    assert got.decode().split("\r\n")[:-1] == REPLIES
    rx = sigrok_lines(path, UART, "uart=rx-data")
    tx = sigrok_lines(path, UART, "uart=tx-data")
    assert as_text(rx) == sent.decode().splitlines()
    assert as_text(tx) == got.decode().splitlines()
    spi = sigrok_lines(path, SPI, "spi=mosi-transfer:miso-transfer")
    for cmd, out in (
            ("-P %s -A uart=rx-data | cut -d' ' -f2 | xxd -r -p" % UART, as_text(rx)),
            ("-P %s -A uart=tx-data | cut -d' ' -f2 | xxd -r -p" % UART, as_text(tx)),
            ("-P %s -A spi=mosi-transfer:miso-transfer" % SPI, spi)):
        block = ["$ sigrok-cli -i capture.vcd -I vcd " + cmd] + out
        assert quoted(block), "docs/simulator.md should quote:\n" + "\n".join(block)
    # the bytes of the SPI exchanges, as the host asked for them
    assert spi[-2:] == ["spi-1: FF FF A5 3C", "spi-1: 03 10 00 00"]

    # the picture: the three pictured requests, their replies and the
    # SPI exchange and the bus between them
    trace = vcd.load(str(path))
    last = max(c for c, _ in trace.edges("D1"))
    bus = [n for n in ("sda", "scl") if n in trace.names()]
    SHOTS.mkdir(parents=True, exist_ok=True)
    rows = plot(path, first - 2000, last + 2000,
                ["D0", "D1", "C2", "B7", "B5", "B6", "i2c"] + bus, SHOTS / "plot-capture.png")
    want = [c if c != " " else "SP" for c in "\n".join(PICTURED)]
    assert rows["D0"][:-1] == ["LF" if c == "\n" else c for c in want] + ["LF"]


def test_the_bus_in_the_capture_is_decoded_as_sigrok_does(captured):
    """With the bit-level bus's wires `sda` and `scl` in the capture (issue
    19), `orfa plot` writes on SDA what sigrok's i2c decoder reads (the
    EEPROM read: S A0 W A 00 A Sr A1 R A FF A FF N P), and draws the
    transaction alone (plot-capture-i2c.png)."""
    sim, _, _, _ = captured
    trace = vcd.load(str(sim.vcd_path))
    if "sda" not in trace.names() or "scl" not in trace.names():
        pytest.skip("this simulator's VCD has no bus wires sda and scl")
    lines = sigrok_lines(sim.vcd_path, I2C, "i2c=addr-data")
    block = ["$ sigrok-cli -i capture.vcd -I vcd -P %s -A i2c=addr-data" % I2C] + lines
    assert quoted(block), "docs/simulator.md should quote:\n" + "\n".join(block)
    theirs = i2c_texts(lines)
    assert " ".join(theirs) == "S A0 W A 00 A Sr A1 R A FF A FF N P"
    busy = trace.edges("i2c")[-2:]
    SHOTS.mkdir(parents=True, exist_ok=True)
    rows = plot(sim.vcd_path, busy[0][0] - 500, busy[1][0] + 500, ["sda", "scl", "i2c"],
                SHOTS / "plot-capture-i2c.png")
    assert rows["sda"][:-1] == theirs
