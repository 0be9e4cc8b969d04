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
from orfa.sim import SimBoard
from sigrok import decode, needs_sigrok

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


def sigrok_lines(path, dec, ann):
    """sigrok-cli's plain output, as a shell prints it (trailing blanks off)."""
    r = subprocess.run(["sigrok-cli", "-i", str(path), "-I", "vcd", "-P", dec, "-A", ann],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return [line.rstrip() for line in r.stdout.splitlines()]


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


def test_the_docs_capture_decodes_as_quoted_and_is_drawn():
    sim, sent, got, first = capture()
    try:
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
        out = SHOTS / "plot-capture.png"
        us = 1e6 / trace.f_cpu
        r = subprocess.run(
            [sys.executable, "-m", "orfa", "plot", str(path), "--signals", "D0", "D1", "C2",
             "B7", "B5", "B6", "i2c"] + bus
            + ["--from", "%.1f" % ((first - 2000) * us), "--to", "%.1f" % ((last + 2000) * us),
               "-v", "-o", str(out)],
            env=dict(os.environ, PYTHONPATH=str(ROOT / "host")), capture_output=True,
            text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        drawn = [line[11:] for line in r.stdout.splitlines() if line.startswith("D0 ")][:-1]
        want = [c if c != " " else "SP" for c in "\n".join(PICTURED)]
        assert drawn == ["LF" if c == "\n" else c for c in want] + ["LF"]
        assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    finally:
        shutil.rmtree(sim.dir, ignore_errors=True)
