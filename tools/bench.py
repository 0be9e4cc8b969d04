#!/usr/bin/env python3
"""ORFA benchmark: cycle-exact figures from the simulator's trace.

For each board: latency from the last request byte (end of its stop bit) to
the first reply byte (start of its start bit) for a few requests, sustained
throughput of back-to-back introspection reads against the wire limit, flash,
static RAM and measured peak stack (the simulator paints SRAM; the firmware
is first put through every driver's requests), and servo pulse accuracy:
width error against the commanded width and its spread (jitter) while
requests stream over the UART back to back. Everything is counted in
simulated CPU cycles, so every figure is exact and repeatable; wall time
enters only the simulator-speed line.

    python3 tools/bench.py [--boards m32d m128s] [--requests 1000]
"""

import argparse
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "host"))

import serial  # noqa: E402

from orfa.sim import SimBoard, firmware_path, parse_trace  # noqa: E402

F_CPU = 7372800
CYCLES_PER_BYTE = 640  # 10 bit times at 115200 baud

LATENCY_REQUESTS = [
    ("V", "V\r", 250),
    ("introspection count", "S AA 00 00 S AB 01 P\r", 640),
    ("driver info", "S AA 00 01 S AB 06 P\r", 640),
]
PIPELINE_REQUEST = "S AA 00 00 S AB 01 P\r"

# ORFA 0.7.5, measured the same way (issue 2).
ORIGINAL = {"V": 1084, "introspection count": 2702, "driver info": 3966}
SRAM_START = {"m32d": 0x60, "m128s": 0x100}
BUDGET_FLASH = 11152
BUDGET_RAM = 992


def footprint(board):
    out = subprocess.run(["avr-size", str(firmware_path(board))], check=True,
                         capture_output=True, text=True).stdout.splitlines()[1].split()
    text, data, bss = int(out[0]), int(out[1]), int(out[2])
    return text + data, data + bss


def read_trace(sim, settle=0.3):
    time.sleep(settle)  # let the simulator flush the last trace lines
    return parse_trace(sim.trace_path.read_text())


def latency(sim, port, request):
    """Cycles from the request's terminator to the first reply byte."""
    before = len(read_trace(sim, 0))
    port.write(request.encode())
    reply = port.readline()
    events = read_trace(sim)[before:]
    rx = [e for e in events if e.kind == "uart rx"]
    end = rx[-1].cycle
    first_tx = next(e for e in events if e.kind == "uart tx" and e.cycle > end)
    return first_tx.cycle - end, reply


def pipeline(sim, port, count):
    """Sends `count` requests in one write; returns (correct, cycles, replies)."""
    expected = port_request_reply(port, PIPELINE_REQUEST)
    before = len(read_trace(sim, 0))
    port.write((PIPELINE_REQUEST * count).encode())
    replies = [port.readline() for _ in range(count)]
    events = read_trace(sim, 0.5)[before:]
    rx = [e for e in events if e.kind == "uart rx"]
    tx = [e for e in events if e.kind == "uart tx"]
    start = rx[0].cycle - CYCLES_PER_BYTE        # start bit of the first request byte
    end = tx[-1].cycle + CYCLES_PER_BYTE          # stop bit of the last reply byte
    correct = sum(1 for r in replies if r == expected)
    return correct, end - start, len(rx)


def port_request_reply(port, request):
    port.write(request.encode())
    return port.readline()


# Requests that reach every driver (register numbers from docs/registers.md).
EXERCISE = {
    "m32d": ["S AA 02 55 0F P", "S AA 06 0F 0F S AB 01 P", "S AA 0B 00 02 02 P",
             "S AA 0A 00 9F 00 00 P", "S AA 0A S AB 03 P", "S AA 0B S AB 09 P",
             "S AA 0C 05 F0 P", "S AA 0D S AB 10 P", "S AA 0E 80 60 00 01 P",
             "S AA 0E 00 00 00 00 P", "S AA 00 01 S AB 3C P"],
    "m128s": ["S AA 02 55 0F P", "S AA 04 0F 0F S AB 01 P", "S AA 07 00 00 02 P",
              "S AA 06 00 9F 00 00 P", "S AA 06 S AB 03 P", "S AA 07 S AB 09 P",
              "S AA 08 05 F0 P", "S AA 09 S AB 10 P", "S AA 00 01 S AB 3C P"],
}
# Servo channels measured: (SP register, [(channel, us, signal)]).
SERVOS = {
    "m32d": (0x13, [(0, 500, "A0"), (1, 1500, "A1"), (9, 2500, "C6"), (13, 1234, "B2")]),
    "m128s": (0x0B, [(0, 500, "servo0"), (9, 1500, "servo9"), (18, 2500, "servo18"),
                     (31, 1234, "servo31")]),
}
SERVO_LOAD = "S AA 00 01 S AB 06 P\r"
# Servo writes timed like the latencies above (request end to reply start):
# 16 channels pulse (M128-S: every other channel, all four counters), then
# one-triple writes, spaced as a host writes them ("S AA 13 03 05 DC P"),
# and 16-triple writes, packed to fit a request ("SAA13" + 96 digits + "P").
# Widths near 1111 us x k end where another channel starts: those channels
# must move. The figure is the slowest write of each kind.
SERVO_WRITE_START = lambda k: 1000 + 100 * (k % 8)
SERVO_WRITE_1 = [(3, 1500), (7, 1111), (0, 2222), (15, 2500), (3, 1600), (8, 1000)]
SERVO_WRITE_16 = [lambda k: 1111, lambda k: 1500, lambda k: 2000 - 41 * k, SERVO_WRITE_START]
SERVO_STREAM = 200


def servo_write_figures(sim, port, board):
    """Slowest 1-triple and 16-triple SP write (cycles) and their wire times."""
    reg = SERVOS[board][0]
    step = 2 if board == "m128s" else 1
    chans = [step * k for k in range(16)]

    def write(req):
        cycles, reply = latency(sim, port, req + "\r")
        assert reply.startswith(b"SW") and b"ERROR" not in reply, (req, reply)
        return cycles, (len(req) + 1) * CYCLES_PER_BYTE

    def write16(width):
        return write("SAA%02X%sP" % (reg, "".join("%02X%04X" % (ch, width(k))
                                                  for k, ch in enumerate(chans))))

    write16(SERVO_WRITE_START)
    one = max(write("S AA %02X %02X %02X %02X P" % (reg, step * k, us >> 8, us & 0xFF))
              for k, us in SERVO_WRITE_1)
    sixteen = max(write16(w) for w in SERVO_WRITE_16)
    stream = servo_stream(sim, port, reg, chans)
    write16(lambda k: 0)
    return one, sixteen, stream


def servo_stream(sim, port, reg, chans, count=SERVO_STREAM):
    """`count` one-triple writes sent back to back (16 channels pulsing):
    (correct replies, % of wire). A board slower than the wire overflows its
    receive buffer and answers ERROR 04."""
    reqs = []
    for i in range(count):
        k, us = SERVO_WRITE_1[i % len(SERVO_WRITE_1)]
        us += 10 * (i // len(SERVO_WRITE_1) % 2)          # every write changes a width
        reqs.append("S AA %02X %02X %02X %02X P\r" % (reg, chans[k], us >> 8, us & 0xFF))
    before = len(read_trace(sim, 0))
    port.write("".join(reqs).encode())
    replies = []
    while len(replies) < count:
        reply = port.readline()
        if not reply:
            break  # the board stopped answering (a reset): no waiting out the rest
        replies.append(reply)
    events = read_trace(sim, 0.5)[before:]
    rx = [e for e in events if e.kind == "uart rx"]
    tx = [e for e in events if e.kind == "uart tx"]
    start = rx[0].cycle - CYCLES_PER_BYTE
    end = tx[-1].cycle + CYCLES_PER_BYTE
    correct = sum(1 for r in replies if r == b"SWAAAAP\r\n")
    return correct, 100.0 * len(rx) * CYCLES_PER_BYTE / (end - start)


def servo_request(board):
    reg, chans = SERVOS[board]
    return "S AA %02X %s P" % (reg, " ".join("%02X %04X" % (ch, us) for ch, us, _ in chans))


def servo_figures(ctl, port, board):
    """Worst width error (us) and width spread (cycles), quiet and under load."""
    reg, chans = SERVOS[board]
    port.write((servo_request(board) + "\r").encode())
    port.readline()
    ctl.wait(F_CPU // 5)  # 10 frames

    def sample(since):
        err, spread, period = 0.0, 0, 0
        for _, us, sig in chans:
            m = ctl.measure(sig, 50, since)
            want = us * F_CPU / 1e6
            err = max(err, abs(m["high"][0] - want), abs(m["high"][1] - want))
            spread = max(spread, m["high"][1] - m["high"][0])
            period = max(period, abs(m["period"][0] - 147456), abs(m["period"][1] - 147456))
        return err / F_CPU * 1e6, spread, period

    quiet = sample(ctl.time() - F_CPU // 6)
    t0 = ctl.time()
    n = 400
    port.write((SERVO_LOAD * n).encode())
    ctl.wait(n * len(SERVO_LOAD) * CYCLES_PER_BYTE)
    loaded = sample(t0)
    for _ in range(n):
        port.readline()
    return quiet, loaded


def heap_start(board):
    out = subprocess.run(["avr-nm", str(firmware_path(board))], check=True,
                         capture_output=True, text=True).stdout
    end = next(line.split()[0] for line in out.splitlines() if line.endswith(" _end"))
    return int(end, 16) - 0x800000


def bench_board(board, count):
    rows = {}
    wall0 = time.monotonic()
    with SimBoard(board, control=True) as sim:
        with serial.Serial(sim.port, 115200, timeout=10) as port:
            for name, request, _ in LATENCY_REQUESTS:
                rows[name] = latency(sim, port, request)
            correct, cycles, rx_bytes = pipeline(sim, port, count)
            rows["servo"] = servo_figures(sim.control, port, board)
            rows["servo write"] = servo_write_figures(sim, port, board)
            for request in EXERCISE[board]:
                port.write((request + "\r").encode())
                port.readline()
        rows["stack"] = sim.control.stack(heap_start(board))
        cycles_total = sim.control.time()
    wall = time.monotonic() - wall0
    wire = rx_bytes * CYCLES_PER_BYTE
    rows["pipeline"] = (correct, cycles, wire)
    rows["speed"] = cycles_total / wall / 1e6
    rows["footprint"] = footprint(board)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--boards", nargs="+", default=["m32d", "m128s"])
    ap.add_argument("--requests", type=int, default=1000)
    args = ap.parse_args()

    results = {b: bench_board(b, args.requests) for b in args.boards}
    width = 34
    print("ORFA benchmark (simulated CPU cycles at 7.3728 MHz; 115200 baud = 640 cycles/byte)")
    print()
    print("%-*s" % (width, "figure") + "".join("%14s" % b for b in args.boards)
          + "%10s%12s" % ("target", "ORFA 0.7.5"))
    for name, request, target in LATENCY_REQUESTS:
        label = "latency %s (cycles)" % name
        print("%-*s" % (width, label)
              + "".join("%14d" % results[b][name][0] for b in args.boards)
              + "%10s%12d" % ("<= %d" % target, ORIGINAL[name]))
    n = args.requests
    label = "pipelined %d: correct replies" % n
    print("%-*s" % (width, label) + "".join("%14s" % ("%d/%d" % (results[b]["pipeline"][0], n))
                                            for b in args.boards) + "%10s%12s" % ("%d/%d" % (n, n), "fails"))
    print("%-*s" % (width, "pipelined: requests/s") + "".join(
        "%14.1f" % (n * F_CPU / results[b]["pipeline"][1]) for b in args.boards)
        + "%10.1f" % (F_CPU / (len(PIPELINE_REQUEST) * CYCLES_PER_BYTE)))
    print("%-*s" % (width, "pipelined: % of wire") + "".join(
        "%14.2f" % (100.0 * results[b]["pipeline"][2] / results[b]["pipeline"][1]) for b in args.boards)
        + "%10s" % ">= 99")
    for i, label in enumerate(("servo write, 1 triple (cycles)", "servo write, 16 triples (cycles)")):
        print("%-*s" % (width, label) + "".join(
            "%14d" % results[b]["servo write"][i][0] for b in args.boards)
            + "%10s" % ("<= 10000" if i == 0 else "< wire"))
    print("%-*s" % (width, "  wire time of the 16-triple write") + "".join(
        "%14d" % results[b]["servo write"][1][1] for b in args.boards))
    label = "servo writes streamed: correct"
    print("%-*s" % (width, label) + "".join(
        "%14s" % ("%d/%d" % (results[b]["servo write"][2][0], SERVO_STREAM)) for b in args.boards)
        + "%10s" % ("%d/%d" % (SERVO_STREAM, SERVO_STREAM)))
    print("%-*s" % (width, "servo writes streamed: % of wire") + "".join(
        "%14.2f" % results[b]["servo write"][2][1] for b in args.boards) + "%10s" % ">= 99")
    print("%-*s" % (width, "flash (B)") + "".join("%14d" % results[b]["footprint"][0] for b in args.boards)
          + "%10s%12d" % ("<= %d" % BUDGET_FLASH, BUDGET_FLASH))
    print("%-*s" % (width, "static RAM (B)") + "".join("%14d" % results[b]["footprint"][1] for b in args.boards)
          + "%10s%12d" % ("<= %d" % BUDGET_RAM, BUDGET_RAM))
    print("%-*s" % (width, "peak stack (B)") + "".join(
        "%14d" % results[b]["stack"]["peak"] for b in args.boards))
    print("%-*s" % (width, "SRAM never touched (%)") + "".join(
        "%14.1f" % (100.0 * (results[b]["stack"]["deepest"] - heap_start(b))
                    / (results[b]["stack"]["ramend"] + 1 - SRAM_START[b])) for b in args.boards)
        + "%10s" % ">= 25")
    print("%-*s" % (width, "servo width error, quiet (us)") + "".join(
        "%14.3f" % results[b]["servo"][0][0] for b in args.boards) + "%10s" % "<= 1.1")
    print("%-*s" % (width, "servo width error, UART load (us)") + "".join(
        "%14.3f" % results[b]["servo"][1][0] for b in args.boards) + "%10s" % "<= 1.1")
    print("%-*s" % (width, "servo jitter, UART load (cycles)") + "".join(
        "%14d" % results[b]["servo"][1][1] for b in args.boards))
    print("%-*s" % (width, "servo period error, load (cycles)") + "".join(
        "%14d" % results[b]["servo"][1][2] for b in args.boards) + "%10s" % "<= 147")
    print("%-*s" % (width, "simulator speed (sim MHz / wall s)") + "".join(
        "%14.1f" % results[b]["speed"] for b in args.boards))
    print()
    print("Targets are the M32-D's (issue 2); flash/RAM budget = ORFA 0.7.5's own M32-D figures.")
    ok = all(results[b]["pipeline"][0] == n for b in args.boards)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
