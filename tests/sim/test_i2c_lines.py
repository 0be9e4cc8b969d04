"""The I2C bus bit by bit (docs/simulator.md, "The lines", "The master's
bits"): the gateway's TWI puts START, bits, ACK and STOP on the wired-AND
lines `sda` and `scl` at the documented points of its SCL period, and a
gateway reset in the high half of a byte's first bit, where silicon would
make a STOP, leaves the slave's frame dropped, not applied."""

import pytest

from conftest import DRV_LAYOUT, require_builds, require_slave, running
from orfa.sim import BOARDS, SimBoard

#: TWBR/TWSR data addresses of the gateway's MCU (for the SCL period).
TWI_REGS = {"m32d": (0x20, 0x21), "m128s": (0x70, 0x71)}


def scl_period(ctl, board):
    twbr, twsr = TWI_REGS[board]
    br = int(ctl.request("peek %d" % twbr), 16)
    ps = int(ctl.request("peek %d" % twsr), 16) & 3
    return 16 + 2 * br * 4 ** ps


def merged(ctl, since):
    """The edges of both lines since `since`: [(cycle, "scl"|"sda", level)],
    in time order (SCL first at a shared cycle: the bus tells it first)."""
    out = [(c, "scl", l) for c, l in ctl.edges("scl", since)]
    out += [(c, "sda", l) for c, l in ctl.edges("sda", since)]
    return sorted(out, key=lambda e: (e[0], e[1] != "scl"))


@pytest.mark.parametrize("board", BOARDS)
def test_the_master_bits_at_their_points(board):
    """An EEPROM write, `S A0 10 5A P`: START (SDA falls P/2 before SCL),
    27 bits each with SCL low P/2 then high P/2 inside a byte, the master's
    data changing P/4 into SCL low and the EEPROM's ACK at SCL's falling
    edge, nothing else moving SDA while SCL is high, and the STOP (SDA
    rises P/2 after SCL); the bits read back are the bytes and ACKs the
    trace has."""
    require_builds([board])
    with running(SimBoard(board, eeproms=(0xA0,), control=True, trace=True)) as b:
        ctl = b.sim.control
        h = scl_period(ctl, board) // 2
        since = ctl.time()
        assert b.ask("S A0 10 5A P") == b"SWAAP\r\n"
        ev = merged(ctl, since)
        twi = b.sim.trace_events(kinds=["twi addr", "twi write", "twi stop"])
    assert ev[0][1:] == ("sda", 0) and ev[1][1:] == ("scl", 0)      # START
    assert ev[1][0] - ev[0][0] == h
    assert ev[-2][1:] == ("scl", 1) and ev[-1][1:] == ("sda", 1)    # STOP
    assert ev[-1][0] - ev[-2][0] == h
    scl = [(c, l) for c, k, l in ev if k == "scl"]
    rises = [c for c, l in scl if l == 1][:-1]                       # the STOP's aside
    falls = [c for c, l in scl if l == 0][1:]                        # the START's aside
    assert len(rises) == len(falls) == 27
    assert all(f - r == h for r, f in zip(rises, falls)), "SCL high half a period"
    starts = [scl[0][0]] + falls[:-1]                                 # each bit's SCL low
    lows = [r - s for s, r in zip(starts, rises)]
    assert all(low == h for i, low in enumerate(lows) if i % 9), lows  # inside a byte
    assert all(low >= h for low in lows)
    # SDA moves only while SCL is low (START and STOP aside): a device's at
    # SCL's falling edge, the master's a quarter period before SCL rises
    # (P/4 into its low half)
    level, moves = 0, []                    # SCL low after the START
    for c, k, l in ev[2:-1]:
        if k == "scl":
            level = l
        else:
            assert level == 0, (c, ev)
            moves.append(c)
    all_rises = [c for c, l in scl if l == 1]
    for c in moves:
        nxt = min(r for r in all_rises if r > c)
        assert c in falls or nxt - c == h - h // 2, (c, nxt)
    # what SDA holds at each rise: three bytes with their ACKs
    def sda_at(cycle):
        lv = 1
        for c, k, l in ev:
            if k == "sda" and c <= cycle:
                lv = l
        return lv
    bits = [sda_at(r) for r in rises]
    got = [(int("".join(map(str, bits[9 * i:9 * i + 8])), 2), bits[9 * i + 8]) for i in range(3)]
    assert got == [(0xA0, 0), (0x10, 0), (0x5A, 0)]
    assert [e.fields for e in twi[-4:-1]] == [("A0", "ack"), ("10", "ack"), ("5A", "ack")]
    assert ev[-1][0] == twi[-1].cycle                                  # `twi stop`: SDA's rise


def test_a_reset_in_a_first_bit_leaves_the_frame_dropped():
    """The gateway (an M32-D, its clock at 0.98 kHz so a bit is 7447 cycles)
    resets in the high half of the first bit of a servo write's sixth byte
    (the channel byte 01, its bit 7 a 0), after one whole triple: SDA rises
    with SCL high there, a STOP on silicon. The model makes it a bus error
    to the devices (docs/simulator.md, "Port pins, stuck devices"), so the
    M32-D slave at 0x12 drops the frame (status 09, no channel moved)
    instead of applying the triple."""
    require_builds(["m32d"])
    slave = 0x12
    sp = DRV_LAYOUT["m32d"]["servo"] + 1
    sim = SimBoard("m32d", control=True, trace=True,
                   slaves=[("m32d", slave, require_slave("m32d", slave))])
    sim.expect_resets = True
    req = ("S%02X%02X0005DC0105DCP\r" % (slave, sp)).encode()
    with running(sim) as b:
        ctl = b.sim.control
        assert b.ask("C0001") == b"C0000\r\n"
        p = scl_period(ctl, "m32d")
        undo = "S %02X %02X 000000 010000 P" % (slave, sp)
        # the bus used once: the gateway's quiet time after its power-up is
        # over (docs/protocol.md, "Abandoned frames"), so both runs start at once
        assert b.ask(undo) == b"SWAAAAAAAP\r\n"
        # one run to see where the bytes are, in cycles from the batch's
        batch = ["time", "rx +2000 %s" % req.hex().upper()]
        began = int(ctl.requests(batch)[0])
        assert b.read_lines(1) == b"SWAAAAAAAP\r\n"
        ev = [e for e in b.sim.trace_events(kinds=["twi write", "twi stretch"])
              if e.cycle > began]
        writes = [e for e in ev if e.kind == "twi write"]
        dc = writes[3]                                                 # the first triple's DC
        assert dc.fields == ("DC", "ack")
        released = [e.cycle for e in ev if e.kind == "twi stretch"
                    and dc.cycle < e.cycle < writes[4].cycle]
        begin = released[0] if released else dc.cycle                 # the channel byte's
        cut = begin - began + p // 2 + p // 4                          # SCL high, its bit 7 (0)
        assert b.ask(undo) == b"SWAAAAAAAP\r\n"
        # the same request, the gateway reset at that point (and let boot)
        mark = b.mark()
        began = int(ctl.requests(batch + ["wait %d" % cut, "reset external",
                                          "wait 400000"])[0])
        b.restore()
        sda = ctl.edges("sda", began)
        scl = ctl.edges("scl", began)
        reset = b.sim.trace_events(mark, ["reset"])[0].cycle
        assert [l for c, l in scl if c <= reset][-1] == 1, "SCL high at the reset"
        assert (reset, 1) in sda, "SDA rises at the reset"
        assert b.ask("S %02X 01 S %02X 01 P" % (slave, slave | 1)) == b"SWASR09P\r\n"
        assert b.ask("S %02X %02X 00 S %02X 04 P" % (slave, sp, slave | 1)) == \
            b"SWAASR00000000P\r\n"
