"""The SPI pins in the simulator's VCD as a logic analyzer sees them
(docs/simulator.md, "SPI", "VCD"): SCK and MOSI as the board's SPI master
clocks them at the rate the firmware set, MISO as the selected part drives
it, the chip selects as the SPI driver moves them. Debian's sigrok-cli, with
sigrok's own `spi` decoder run once per chip select in that channel's SPI
mode, decodes exactly the exchanges the host asked for through the gateway
(what it sent on MOSI and got back from MISO), transfer by transfer, and the
bytes the trace's `spi` lines give, each at its cycle."""

import shutil

import pytest

from conftest import require_builds
from orfa import boardmap
from orfa.board import Board
from orfa.sim import BOARDS, SimBoard
from sigrok import decode, needs_sigrok

pytestmark = needs_sigrok

WIP = 36864 + 2000                 # eeprom25's write cycle (5 ms) and some
ADC_MV = {3: 1234}

#: Chip-select pins of the three parts (free port lines of each board).
CS_PINS = {"m32d": ["C2", "C3", "D6"], "m128s": ["A0", "A1", "A2"]}
#: channel -> (part option after its pin, SPI mode, LSB first, clock divider:
#: SCK = F_CPU / 2^(div+1)): the fastest clock, the slowest, and mode 3 LSB first
CHANNELS = {0: ("", 0, False, 0), 1: (None, 0, False, 6), 2: (":mode=3:lsb", 3, True, 2)}


def spi_pins(board):
    """{"SCK": "B7", "MOSI": ..., "MISO": ..., "SS": ...}: the board's SPI pins."""
    return {p.function[4:]: p.signal for p in boardmap.load(board).pins
            if p.function.startswith("SPI_")}


MISO = {board: spi_pins(board)["MISO"] for board in BOARDS}


def parts(board):
    pins = CS_PINS[board]
    return ["eeprom25@%s%s" % (pins[0], CHANNELS[0][0]), "mcp3008@%s" % pins[1],
            "eeprom25@%s%s" % (pins[2], CHANNELS[2][0])]


def exchanges(spi, ctl):
    """The host's exchanges, channel by channel: [(channel, sent, received)]."""
    done = []

    def xfer(ch, data):
        _, mode, lsb, div = CHANNELS[ch]
        spi.configure(clock_div=div, mode=mode, lsb_first=lsb)
        done.append((ch, bytes(data), spi.transfer(ch, bytes(data))))
        return done[-1][2]

    for ch, addr, data in ((0, 0x10, b"\xA5\x3C\x81"), (2, 0x40, b"\x12\xF0")):
        xfer(ch, b"\x06")                                   # WREN
        xfer(ch, bytes([0x02, addr]) + data)                # WRITE
        ctl.wait(WIP)
        assert xfer(ch, bytes([0x03, addr]) + bytes(len(data)))[2:] == data
    ch, mv = next(iter(ADC_MV.items()))
    got = xfer(1, bytes([0x01, 0x80 | ch << 4, 0x00]))     # mcp3008, single-ended
    assert ((got[1] & 3) << 8 | got[2]) == 1024 * mv // 5000
    return done


def run(board):
    """A gateway with the three parts and --vcd; the host binds the chip
    selects and makes its exchanges. Returns the sim (stopped, its
    directory kept), the exchanges and the capture's path."""
    require_builds([board])
    sim = SimBoard(board, spi=parts(board), adc=ADC_MV, control=True, vcd=True,
                   trace=True).start()
    try:
        with sim.gateway() as gw:
            spi = Board(gw).spi
            for ch, pin in enumerate(CS_PINS[board]):   # every chip select high first
                spi.bind(ch, pin[0], int(pin[1]))
            # nothing selected: MISO shows 1, what the master reads
            assert sim.control.pin(MISO[board]) == (1, "in spi")
            done = exchanges(spi, sim.control)
        sim.control.wait(1000)
    except BaseException:
        sim.stop()
        raise
    sim.stop(keep_dir=True)
    return sim, done, sim.vcd_path


def sigrok_spi(path, board, cs, mode, lsb):
    """sigrok's spi decoder on the board's SPI pins with chip select CS:
    ([(mosi bytes, miso bytes)] per transfer, [(begin cycle, mosi, miso)]
    per byte)."""
    pins = spi_pins(board)
    dec = "spi:clk=%s:mosi=%s:miso=%s:cs=%s:cpol=%d:cpha=%d:bitorder=%s" % (
        pins["SCK"], pins["MOSI"], pins["MISO"], cs, mode >> 1, mode & 1,
        "lsb-first" if lsb else "msb-first")
    rows, _ = decode(path, dec, "spi=mosi-data:miso-data:mosi-transfer:miso-transfer")

    def data(row):
        return [bytes.fromhex(text) for _, _, text in rows.get(row, [])]
    # a chip select low from power-up until the driver took it: no bytes
    transfers = [(o, i) for o, i in zip(data("MOSI transfer"), data("MISO transfer")) if o]
    assert all(len(o) == len(i) for o, i in transfers)
    mosi, miso = rows.get("MOSI data", []), rows.get("MISO data", [])
    assert [b for b, _, _ in mosi] == [b for b, _, _ in miso]
    return transfers, [(begin, int(o, 16), int(i, 16))
                       for (begin, _, o), (_, _, i) in zip(mosi, miso)]


@pytest.mark.parametrize("board", BOARDS)
def test_sigrok_decodes_each_chip_select_byte_for_byte(board):
    """Per chip select, sigrok's transfers are the host's exchanges on that
    channel (MOSI: the bytes sent; MISO: the bytes the transfer returned),
    and its bytes are the trace's `spi CS MOSI MISO` lines, at the SPI clock
    the firmware set for the channel: sigrok starts a byte at its first
    sampling edge, 1 (CPHA 0) or 2 (CPHA 1) SCK half periods after the byte
    began, and the trace's line is at its end, 16 half periods after that
    (half = 2^div cycles), within a cycle."""
    sim, done, path = run(board)
    try:
        events = sim.trace_events(kinds=["spi"])
        for ch, pin in enumerate(CS_PINS[board]):
            _, mode, lsb, div = CHANNELS[ch]
            transfers, data = sigrok_spi(path, board, pin, mode, lsb)
            assert transfers == [(o, i) for c, o, i in done if c == ch], pin
            want = [(e.cycle, int(e.fields[1], 16), int(e.fields[2], 16))
                    for e in events if e.fields[0] == pin]
            assert [d[1:] for d in data] == [w[1:] for w in want], pin
            half = 2 ** div
            off = [begin - (end - 16 * half) - (1 + (mode & 1)) * half
                   for (begin, _, _), (end, _, _) in zip(data, want)]
            assert all(abs(x) <= 1 for x in off), (pin, half, off)
    finally:
        shutil.rmtree(sim.dir, ignore_errors=True)
