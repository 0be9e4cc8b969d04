"""The I2C bus in the simulator's VCD as a logic analyzer's capture
(docs/simulator.md, "The lines" and "VCD"): Debian's sigrok-cli, with
sigrok's own `i2c` decoder on the wires `sda` and `scl`, decodes exactly
what the gateway put on the bus and read from it: START, repeated START
and STOP, every address with its R/W bit, every data byte, every ACK and
NACK, equal to the host's requests and replies and to the trace's `twi`
lines. On the bus: an EEPROM at 0xA0 (a write, then a read after a
repeated START), an M128-S slave board at 0x10 that stretches SCL (a servo
write of 16 triples, then reads) and an address nobody answers (NACK);
each gateway board in turn."""

import re
import shutil

import pytest
import serial

from conftest import DRV_LAYOUT, REPLY_TIMEOUT, require_builds, require_slave
from orfa.sim import BOARDS, SimBoard
from sigrok import i2c_view, needs_sigrok

SLAVE = 0x10
SP = DRV_LAYOUT["m128s"]["servo"] + 1          # the M128-S's servo widths (3 bytes a channel)
TRIPLES = " ".join("%02X%04X" % (ch, 1000 + 37 * ch) for ch in range(16))
#: (request, the reply it must get)
REQUESTS = [
    ("S A0 10 48 69 P", "SWAAAP"),
    ("S A0 10 S A1 02 P", "SWASR4869P"),
    ("S 42 P", "ERROR 06"),                                  # nobody there
    ("S %02X %02X %s P" % (SLAVE, SP, TRIPLES), "SW" + "A" * 49 + "P"),
    # channels 3..5 read back; channel 0 and the EEPROM's next byte (erased)
    ("S %02X %02X 03 S %02X 06 P" % (SLAVE, SP, SLAVE | 1),
     "SWAASR" + "".join("%04X" % (1000 + 37 * ch) for ch in range(3, 6)) + "P"),
    ("S %02X %02X 00 S %02X 02 S A1 01 P" % (SLAVE, SP, SLAVE | 1),
     "SWAASR%04XSRFFP" % 1000),
]

pytestmark = needs_sigrok


def host_view(request, reply):
    """What the bus carried for one request, from the request's text and
    the reply the host read: [("S"|"Sr"|"P"), ("AW"|"AR", 7-bit address,
    ack), ("DW"|"DR", byte, ack)], ack 1 for ACK, 0 for NACK."""
    frames = [bytes.fromhex(f) for f in re.findall(r"S((?: [0-9A-F]{2,})+)", request)]
    out = []
    if reply.startswith("ERROR"):
        # only an absent address here: one frame, its address NACKed
        assert len(frames) == 1 and len(frames[0]) == 1, request
        return ["S", ("AW", frames[0][0] >> 1, 0), "P"]
    parts = re.findall(r"SW([AN]*)|SR((?:[0-9A-F]{2})*)", reply[:-1])
    assert reply.endswith("P") and len(parts) == len(frames), (request, reply)
    for k, (frame, (acks, data)) in enumerate(zip(frames, parts)):
        addr, *rest = frame
        out.append("Sr" if k else "S")
        out.append(("AR" if addr & 1 else "AW", addr >> 1, 1))
        if addr & 1:
            got = bytes.fromhex(data)
            assert len(got) == rest[0], (request, reply)
            out += [("DR", b, int(i < len(got) - 1)) for i, b in enumerate(got)]
        else:
            # a letter for every data byte (the register byte among them)
            assert len(acks) == len(rest), (request, reply)
            out += [("DW", b, int(a == "A")) for b, a in zip(rest, acks)]
    return out + ["P"]


def trace_view(events):
    """The same from the trace's `twi` lines."""
    out, open_ = [], False
    for e in events:
        if e.kind == "twi start":
            out.append("Sr" if open_ else "S")
            open_ = True
        elif e.kind == "twi stop":
            out.append("P")
            open_ = False
        elif e.kind == "twi addr":
            a = int(e.fields[0], 16)
            out.append(("AR" if a & 1 else "AW", a >> 1, int(e.fields[1] == "ack")))
        elif e.kind in ("twi write", "twi read"):
            kind = "DW" if e.kind == "twi write" else "DR"
            out.append((kind, int(e.fields[0], 16), int(e.fields[1] == "ack")))
    return out


def run_capture(sim, talk):
    """Starts `sim` (made with vcd=True, trace=True, control=True), calls
    talk(port) with its serial port open, lets 20000 cycles pass and stops
    it, keeping its directory (the VCD, the trace) for the caller to
    remove."""
    sim.start()
    try:
        with serial.Serial(sim.port, 115200, timeout=REPLY_TIMEOUT) as port:
            talk(port)
        sim.control.wait(20000)
    except BaseException:
        sim.stop()
        raise
    sim.stop(keep_dir=True)
    return sim


@pytest.fixture(scope="module", params=BOARDS)
def capture(request):
    """A gateway with the EEPROM and the M128-S slave, --vcd and --trace;
    the host sends REQUESTS and reads each reply. The host's view, the
    trace's, sigrok's, and the sim (its trace)."""
    board = request.param
    require_builds([board])
    host = []

    def talk(port):
        for req, want in REQUESTS:
            port.write(req.encode() + b"\r")
            reply = port.readline().decode().strip()
            assert reply == want, (req, reply)
            host.extend(host_view(req, reply))

    sim = run_capture(SimBoard(board, eeproms=(0xA0,), control=True, vcd=True, trace=True,
                               slaves=[("m128s", SLAVE, require_slave("m128s", SLAVE))]), talk)
    try:
        yield host, trace_view(sim.trace_events(kinds=["twi"])), i2c_view(sim.vcd_path), sim
    finally:
        shutil.rmtree(sim.dir, ignore_errors=True)


def test_sigrok_decodes_what_the_host_sent_and_read(capture):
    host, _, decoded, _ = capture
    assert decoded == host


def test_sigrok_decodes_what_the_trace_says(capture):
    _, trace, decoded, _ = capture
    assert decoded == trace


def test_the_capture_has_each_kind(capture):
    """The capture is the one asked for: repeated STARTs, a NACKed address,
    a NACKed last read, and the slave stretched SCL (the trace's `twi
    stretch 10` lines) without changing what is decoded."""
    _, _, decoded, sim = capture
    assert decoded.count("Sr") == 4
    assert ("AW", 0x42 >> 1, 0) in decoded
    assert [d for d in decoded if d[0] == "DR" and not d[2]] == \
        [("DR", 0x69, 0), ("DR", (1000 + 37 * 5) & 0xFF, 0), ("DR", 1000 & 0xFF, 0),
         ("DR", 0xFF, 0)]
    assert [s for s in sim.stretches() if s[1] == SLAVE], "the slave never stretched"

