"""A write frame the gateway abandons is applied by no slave (docs/protocol.md,
"Abandoned frames"; docs/registers.md, "On a slave board").

A robot of one gateway (each board in turn) and two slave boards (an M128-S at
0x10, an M32-D at 0x12). A servo write of 16 triples, or a GPIO mode write, to
one slave is cut at several points: a device holds SCL low there for longer
than the gateway waits (the gateway gives up: `ERROR 07`), or the gateway
resets there. The next request comes right after, to the same slave or to the
other one. Nothing of the cut write is applied (registers read back, and the
servo pins stay quiet), the slave's status register says `09` once data had
arrived, the bus is idle afterwards, and the next request is served as itself.
A cut follows the bus, not the clock: the batch waits for its byte to end
(`wait i2c`) and cuts a fixed number of cycles after it, so it lands in the
same byte however late the wall clock delivers the batch and wherever the
gateway's main loop and clock interrupt were when the request came."""

import pytest

from conftest import (DRV_LAYOUT, DROPPED, F_CPU, M128S, M32D, OK, SLAVES, mode, sp,
                      status)
MS = F_CPU // 1000
LEAD = 2000                      # cycles from the batch to the request's first bit
REACH = 200000                   # the write's bytes are on the bus by then (cycles)
#: Cycles from the end of a byte (its acknowledge's SCL falling edge) to the
#: cut in the middle of the next one: that begins 40..190 cycles later (the
#: slave's stretch, the gateway's reaction, over 1600 random phases; seen
#: later than MID in a few of some 5000 cuts: those fell between the two
#: bytes, which leaves the slave the same bytes) and takes 9 SCL periods
#: (666 cycles at 100 kHz). After the last byte the cut is at once: the slave
#: still holds SCL after its acknowledge, the STOP comes 190 cycles later.
MID = 400
HOLD = 100000                    # SCL held this long: more than the gateway waits (9.7 ms)
AFTER = 30000                    # then the next request comes this soon


def write_of(kind, addr):
    """The write that gets cut, as the request's text (no spaces)."""
    if kind == "servo":
        return "S%02X%02X%sP" % (addr, sp(addr), "".join("%02X05DC" % ch for ch in range(16)))
    return "S%02X%02X0F0FP" % (addr, mode(addr))      # lines 0-3 outputs


def applied_nothing(b, addr, since):
    """The slave's servos read 0 and its first channel's pin never moved;
    its GPIO port is all inputs."""
    a = addr
    widths = b.ask("S %02X %02X 00 S %02X 20 P" % (a, sp(a), a | 1))
    assert widths == b"SWAASR" + b"0" * 64 + b"P\r\n", widths
    assert b.ask("S %02X %02X S %02X 01 P" % (a, mode(a), a | 1)) == b"SWASR00P\r\n"
    pin = DRV_LAYOUT[SLAVES[a]]["servo_pins"][0]
    assert b.sim.control.slave(a).edges(pin, since) == []


def bytes_of(kind, addr):
    """The write's bytes on the bus, its address included."""
    return 1 + (len(write_of(kind, addr)) - 4) // 2


def cut_batch(b, kind, addr, after, fault):
    """The write on the serial line and, `after` bytes of it on the bus
    after its address, the fault: SCL held, or the gateway reset. The
    batch's requests up to the fault (its fourth reply: the fault's cycle);
    its first reply is the cycle the write began at."""
    req = (write_of(kind, addr) + "\r").encode()
    last = after + 1 == bytes_of(kind, addr)
    lines = ["time", "rx +%d %s" % (LEAD, req.hex().upper()),
             "wait i2c %d %d" % (after + 1, REACH), "wait %d" % (0 if last else MID)]
    if fault == "hold":
        lines += ["i2c hold-scl on", "wait %d" % HOLD, "i2c hold-scl off"]
    else:
        lines += ["reset external"]
    return lines


def assert_landed(b, kind, addr, after, out):
    """The cut of cut_batch (replies OUT) came where it was meant: after the
    byte `wait i2c` waited for and before the next one ended (SCL fell
    fewer than 9 times since); or after the last one, before the STOP (the
    bus busy from the write's START on)."""
    ctl = b.sim.control
    began, waited, cut = int(out[0]), int(out[2]), int(out[3])
    if after + 1 == bytes_of(kind, addr):
        busy = [level for c, level in ctl.edges("i2c", began) if c <= cut]
        assert busy == [1], (began, cut, busy)
        return
    falls = [c for c, level in ctl.edges("scl", waited + 1) if not level and c <= cut]
    assert len(falls) < 9, (waited, cut, falls)


#: after how many of its bytes after the address the write is cut: in the
#: register byte, in data, in the last byte, before the STOP
CUTS = {"servo": [0, 1, 4, 25, 48, 49], "gpio": [0, 1, 2, 3]}
CASES = [(kind, after) for kind in CUTS for after in CUTS[kind]]


@pytest.mark.parametrize("victim", [M128S, M32D], ids=["m128s@10", "m32d@12"])
@pytest.mark.parametrize("kind,after", CASES, ids=["%s-%d" % c for c in CASES])
@pytest.mark.parametrize("fault", ["hold", "reset"])
def test_cut_write_applies_nothing_next_to_same(pair_rb, victim, kind, after, fault):
    b = pair_rb
    ctl = b.sim.control
    lines = cut_batch(b, kind, victim, after, fault)
    nxt = b"S%02X01S%02X01P\r" % (victim, victim | 1)   # the status, first of all
    out = ctl.requests(lines + ["wait %d" % AFTER, "rx +10 %s" % nxt.hex().upper()])
    began = int(out[0])
    assert_landed(b, kind, victim, after, out)
    want_status = DROPPED if after >= 2 else OK     # data had arrived (the register byte is not)
    got = b.read_lines(2 if fault == "hold" else 1)
    if fault == "hold":
        assert got == b"ERROR 07\r\nSWASR%02XP\r\n" % want_status, got
    else:
        assert got == b"SWASR%02XP\r\n" % want_status, got
    assert ctl.i2c()["sda"] == 1 and ctl.i2c()["scl"] == 1
    applied_nothing(b, victim, began)


@pytest.mark.parametrize("victim", [M128S, M32D], ids=["m128s@10", "m32d@12"])
@pytest.mark.parametrize("kind,after", [("servo", 1), ("servo", 25), ("servo", 49), ("gpio", 2)],
                         ids=["servo-1", "servo-25", "servo-49", "gpio-2"])
@pytest.mark.parametrize("fault", ["hold", "reset"])
def test_cut_write_applies_nothing_next_to_other(pair_rb, victim, kind, after, fault):
    """The next request goes to the other slave: a servo write it applies,
    while the cut one is dropped, not applied by the START that addressed
    the other."""
    b = pair_rb
    ctl = b.sim.control
    other = M32D if victim == M128S else M128S
    lines = cut_batch(b, kind, victim, after, fault)
    nxt = b"S%02X%02X0105DCP\r" % (other, sp(other))       # channel 1 at 1500 us
    out = ctl.requests(lines + ["wait %d" % AFTER, "rx +10 %s" % nxt.hex().upper()])
    began = int(out[0])
    assert_landed(b, kind, victim, after, out)
    got = b.read_lines(2 if fault == "hold" else 1)
    assert got == (b"ERROR 07\r\n" if fault == "hold" else b"") + b"SWAAAAP\r\n", got
    assert status(b, victim) == (DROPPED if after >= 2 else OK)
    applied_nothing(b, victim, began)
    assert status(b, other) == OK
    assert b.ask("S %02X %02X 01 S %02X 02 P" % (other, sp(other), other | 1)) \
        == b"SWAASR05DCP\r\n"


def test_a_healthy_write_right_after_is_applied(pair_rb):
    """The fence does not eat the next write: the same write, sent again
    right after a cut one, is applied whole."""
    b = pair_rb
    ctl = b.sim.control
    lines = cut_batch(b, "servo", M32D, 25, "hold")
    again = (write_of("servo", M32D) + "\r").encode()
    ctl.requests(lines + ["wait %d" % AFTER, "rx +10 %s" % again.hex().upper()])
    assert b.read_lines(2) == b"ERROR 07\r\nSW" + b"A" * 49 + b"P\r\n"
    assert status(b, M32D) == OK
    reply = b.ask("S 12 %02X 00 S 13 20 P" % sp(M32D))
    assert reply == b"SWAASR" + b"05DC" * 16 + b"P\r\n", reply


def test_an_old_fence_never_delays_an_error(pair_rb):
    """The quiet time after a fault is over for good once it has passed: a
    request long after it (here 4 x 256 clock ticks + 20 ms, where a clock
    read modulo 256 ticks would think the fault fresh) with the bus stuck
    again gets its ERROR within 10 ms, as the first did."""
    b = pair_rb
    ctl = b.sim.control
    req = b"S1201S1301P\r"
    mark = b.mark()
    try:
        ctl.requests(["i2c hold-scl on", "rx +2000 %s" % req.hex().upper()])
        assert b.read_lines(1) == b"ERROR 06\r\n"
        off = [e.cycle for e in b.events(mark, ["twi off"])]
        assert len(off) == 1, off                          # the gateway gave up there
        end = off[0] + 4 * 256 * 2048 + 20 * MS             # the next request's last bit
        ctl.rx(end - 10 * ctl.line()["bit"] * len(req), req)
        assert b.read_lines(1) == b"ERROR 06\r\n"
        tx = [e.cycle for e in b.events(mark, ["uart tx"]) if e.cycle > end]
        assert 9 * MS < tx[0] - end < 10 * MS, tx[0] - end
    finally:
        ctl.i2c_hold_scl(False)
