"""Bus faults in the middle of a byte (issue 19; docs/protocol.md, the
bus-fault table; docs/simulator.md, "Faults in the middle of a byte").

A robot of one gateway (each board in turn) and two slave boards (an M128-S
at 0x10, an M32-D at 0x12), as in test_abandoned.py. A write or a read to
one slave meets a fault at a chosen byte and bit of its transaction:

* `i2c arb BYTE BIT`: a device pulls SDA low for that bit; where the
  gateway sends a 1 it loses arbitration (TWSR 0x38);
* `i2c glitch start|stop BYTE BIT`: a START or STOP condition in that bit,
  a bus error (0x00) for the gateway's TWI and the addressed slave's.

The gateway answers `ERROR 06` before the address was acknowledged and
`ERROR 07` after, soon after the fault (no bus timeout is waited for);
nothing of a cut write is applied and the slave's status says DROPPED
where data had arrived; the gateway sends no STOP; the lines are high and
the next request is served, to the same slave or the other."""

import shutil

import pytest

from conftest import (DROPPED, F_CPU, M128S, M32D, OK, mode, require_builds,
                      require_slave, running, sp, status)
from orfa.sim import REPO_ROOT, SimBoard
from test_abandoned import applied_nothing
from sigrok import i2c_view, needs_sigrok
from test_sigrok_i2c import run_capture, trace_view

MS = F_CPU // 1000
SLOW_P = 7447        # cycles: the SCL period at the slowest clock, C0001
LEAD = 2000          # cycles from the batch to the request's first bit


@pytest.fixture
def rb(pair_rb):
    # a servo pulse a test before left running ends within a 20 ms frame
    # or two: none is seen as a write applied
    pair_rb.sim.control.wait(45 * MS)
    return pair_rb


def servo_write(addr):
    """Channels 0 and 1 to 1500 us: bytes on the bus 0 address, 1 register,
    2..4 `00 05 DC`, 5..7 `01 05 DC`."""
    return "S%02X%02X0005DC0105DCP" % (addr, sp(addr))


def first_one(byte):
    """The first bit (MSB first) that is 1 in `byte`."""
    return next(k for k in range(8) if byte & (0x80 >> k))


def faulted(b, fault, req):
    """`fault` armed, then `req` (text, without its end) from the serial
    line: the reply, the cycles from the request's end to the reply's first
    byte, the trace mark before it and the cycle the request began."""
    ctl = b.sim.control
    data = (req + "\n").encode()
    mark = b.mark()
    out = ctl.requests([fault, "rx +%d %s" % (LEAD, data.hex().upper())])
    end = int(out[1])
    reply = b.read_lines(1)
    tx = [e.cycle for e in b.events(mark, ["uart tx"]) if e.cycle > end]
    return reply, tx[0] - end, mark, end - 10 * ctl.line()["bit"] * len(data)


def after_fault(b, mark, victim):
    """The gateway never sent a STOP after the fault; the lines are high
    (once the quiet time is over: a slave that was sending lets SDA go when
    it drops the frame); every fault fired."""
    kinds = [e.kind for e in b.events(mark, ["twi"])]
    fault = next(i for i, k in enumerate(kinds) if k in ("twi arb-lost", "twi glitch"))
    rest = kinds[fault:] + ["twi start"]
    assert "twi stop" not in rest[:rest.index("twi start")], kinds
    b.sim.control.wait(40 * MS)
    assert b.sim.control.i2c()["sda"] == 1 and b.sim.control.i2c()["scl"] == 1
    assert b.sim.control.i2c_armed() == "none"


#: (fault, byte, bit or None: the first 1 of that byte) on servo_write:
#: the reply, whether data had arrived at the slave (the register byte
#: does not count)
WRITE_CUTS = [
    ("arb", 0, None, b"ERROR 06", False),          # the address
    ("arb", 1, None, b"ERROR 07", False),          # the register byte
    ("arb", 3, 5, b"ERROR 07", True),              # 05: its first 1
    ("arb", 7, 0, b"ERROR 07", True),              # DC, the last byte
    ("glitch start", 0, 4, b"ERROR 06", False),
    ("glitch stop", 0, 8, b"ERROR 06", False),     # the address's acknowledge
    ("glitch start", 2, 8, b"ERROR 07", False),    # the first data byte not in yet
    ("glitch stop", 3, 8, b"ERROR 07", True),
    ("glitch start", 4, 1, b"ERROR 07", True),
    ("glitch stop", 7, 7, b"ERROR 07", True),
]
WRITE_IDS = ["%s-%d-%s" % (c[0].replace(" ", "-"), c[1], c[2]) for c in WRITE_CUTS]


@pytest.mark.parametrize("victim", [M128S, M32D], ids=["m128s@10", "m32d@12"])
@pytest.mark.parametrize("fault,byte,bit,want,data_in", WRITE_CUTS, ids=WRITE_IDS)
def test_write_cut_mid_byte_applies_nothing(rb, victim, fault, byte, bit, want, data_in):
    b = rb
    req = servo_write(victim)
    if bit is None:
        bit = first_one(int(req[1 + 2 * byte:3 + 2 * byte], 16))
    reply, lat, mark, began = faulted(b, "i2c %s %d %d" % (fault, byte, bit), req)
    assert reply == want + b"\r\n", reply
    print("%s %d %d: %s after %d cycles (%.2f ms)" % (fault, byte, bit, want.decode(), lat,
                                                     lat / MS))
    assert lat < 2 * MS, lat
    ev = [(e.kind,) + e.fields for e in b.events(mark, ["twi"])]
    if fault == "arb":
        assert ("twi arb-lost",) in ev, ev
    else:
        assert ("twi glitch", fault.split()[1]) in ev and ("twi bus-error",) in ev, ev
        # the slave's TWI takes part from its address's acknowledge on
        slave_error = ("twi bus-error", "%02X" % victim) in ev
        assert slave_error == (byte >= 1 or bit == 8), ev
    after_fault(b, mark, victim)
    # a bus error: the slave recovered with TWSTO at once; a frame the
    # gateway left (arbitration lost) the slave dropped after 30 ms of
    # quiet, resetting its TWI
    off = [e.cycle for e in b.events(mark, ["twi off"]) if e.fields == ("%02X" % victim,)]
    assert len(off) == (1 if fault == "arb" and byte >= 1 else 0), off
    # the next request to the same slave, its status first of all
    assert status(b, victim) == (DROPPED if data_in else OK)
    applied_nothing(b, victim, began)
    # and the write itself, whole this time
    assert b.ask(servo_write(victim)) == b"SWAAAAAAAP\r\n"
    assert status(b, victim) == OK
    assert b.ask("S %02X %02X 01 S %02X 02 P" % (victim, sp(victim), victim | 1)) \
        == b"SWAASR05DCP\r\n"


@pytest.mark.parametrize("fault", ["arb 3 4", "glitch stop 3 3"])
def test_next_request_to_the_other_slave(rb, fault):
    """A GPIO mode write to the M32-D (bytes 0 address, 1 register, 2 and 3
    `0F`: the first 1 of 0F is bit 4) cut in its last byte; the next
    request, a write to the M128-S, is applied; the cut one is not."""
    b = rb
    req = "S%02X%02X0F0FP" % (M32D, mode(M32D))       # lines 0-3 outputs
    reply, _, mark, _ = faulted(b, "i2c " + fault, req)
    assert reply == b"ERROR 07\r\n"
    assert b.ask("S %02X %02X 01 05 DC P" % (M128S, sp(M128S))) == b"SWAAAAP\r\n"
    after_fault(b, mark, M32D)
    assert status(b, M32D) == DROPPED
    assert b.ask("S %02X %02X S %02X 01 P" % (M32D, mode(M32D), M32D | 1)) == b"SWASR00P\r\n"
    assert status(b, M128S) == OK
    assert b.ask("S %02X %02X 01 S %02X 02 P" % (M128S, sp(M128S), M128S | 1)) \
        == b"SWAASR05DCP\r\n"


def read_req(addr):
    """Channel 0's width: bytes 0 address, 1 register, 2 `00`, 3 the read
    address (repeated START), 4 and 5 the two bytes read (ACK, NACK)."""
    return "S%02X%02X00S%02X02P" % (addr, sp(addr), addr | 1)


@pytest.mark.parametrize("victim", [M128S, M32D], ids=["m128s@10", "m32d@12"])
def test_read_faults(rb, victim):
    """In a read: the device's low bit in a byte the slave sends is read as
    0 (no fault: the master does not send there); on the master's ACK it
    changes nothing; in the read address after the repeated START it is
    ERROR 06; on the master's NACK after the last byte the master loses
    arbitration (ERROR 07) and the slave, which saw an ACK, goes on until it
    drops the frame; a glitch in a byte the slave sends is a bus error for
    both. After each the next request is served."""
    b = rb
    a = victim
    assert b.ask("S %02X %02X 00 05 DC P" % (a, sp(a))) == b"SWAAAAP\r\n"
    reply, _, _, _ = faulted(b, "i2c arb 4 5", read_req(a))
    assert reply == b"SWAASR01DCP\r\n"                 # 05 read as 01
    reply, _, _, _ = faulted(b, "i2c arb 4 8", read_req(a))
    assert reply == b"SWAASR05DCP\r\n"
    # the read address after the repeated START (11, 13: bit 3 is a 1) is
    # an address too: ERROR 06
    for fault, want in (("arb 3 3", b"ERROR 06"), ("glitch start 3 8", b"ERROR 06"),
                        ("arb 5 8", b"ERROR 07"), ("glitch stop 4 2", b"ERROR 07"),
                        ("glitch start 5 8", b"ERROR 07")):
        reply, lat, mark, _ = faulted(b, "i2c " + fault, read_req(a))
        assert reply == want + b"\r\n", (fault, reply)
        print("read, %s: %s after %d cycles (%.2f ms)" % (fault, want.decode(), lat, lat / MS))
        if fault.startswith("glitch"):
            assert ("twi bus-error", "%02X" % a) in [(e.kind,) + e.fields
                                                     for e in b.events(mark, ["twi"])]
        after_fault(b, mark, a)
        assert status(b, a) == OK
        assert b.ask(read_req(a).replace("S", "S ")) == b"SWAASR05DCP\r\n"


def test_a_lost_bit_addresses_the_other_slave(rb):
    """12 with its bit 6 pulled low reads 11: the M128-S at 10 is addressed
    for a read and starts sending to a master that went away (ERROR 06). It
    drops that frame after 30 ms; the gateway's next START comes after it,
    and both slaves serve as before."""
    b = rb
    reply, _, mark, began = faulted(b, "i2c arb 0 6", servo_write(M32D))
    assert reply == b"ERROR 06\r\n"
    ev = [(e.kind,) + e.fields for e in b.events(mark, ["twi"])]
    assert ("twi addr", "11", "ack") in ev, ev
    after_fault(b, mark, M32D)
    # (the gateway's TWI was no longer the master when it reset it)
    assert [e.fields for e in b.events(mark, ["twi off"])] == [("10",)]
    assert status(b, M128S) == OK and status(b, M32D) == OK
    applied_nothing(b, M32D, began)
    assert b.ask(servo_write(M32D)) == b"SWAAAAAAAP\r\n"


def test_x_after_a_fault(rb):
    """`X` right after a fault frees nothing that is held, answers X, and
    the bus serves the next request."""
    b = rb
    reply, _, mark, _ = faulted(b, "i2c glitch start 3 4", servo_write(M128S))
    assert reply == b"ERROR 07\r\n"
    assert b.ask("X") == b"X\r\n"
    after_fault(b, mark, M128S)
    assert status(b, M128S) == DROPPED
    assert b.ask(servo_write(M128S)) == b"SWAAAAAAAP\r\n"
    assert status(b, M128S) == OK


def test_a_bit_the_master_sends_low_changes_nothing(rb):
    """The device's low bit where the gateway sends a 0 is no fault: the
    write goes through whole."""
    b = rb
    reply, _, _, _ = faulted(b, "i2c arb 0 0", servo_write(M32D))   # 12: its MSB is 0
    assert reply == b"SWAAAAAAAP\r\n"
    assert b.sim.control.i2c_armed() == "none"
    assert b.ask("S %02X %02X 01 S %02X 02 P" % (M32D, sp(M32D), M32D | 1)) \
        == b"SWAASR05DCP\r\n"


def test_a_fault_past_the_last_byte_is_missed(rb):
    """A fault armed for a byte the transaction does not have is dropped at
    its STOP (`twi fault missed`); the next transaction is not hit."""
    b = rb
    reply, _, mark, _ = faulted(b, "i2c glitch start 8 3", servo_write(M32D))   # bytes 0..7
    assert reply == b"SWAAAAAAAP\r\n"
    assert ("twi fault", "missed") in [(e.kind,) + e.fields for e in b.events(mark, ["twi"])]
    assert b.sim.control.i2c_armed() == "none"
    assert b.ask(servo_write(M32D)[:-1] + "0205DCP") == b"SW" + b"A" * 10 + b"P\r\n"


def test_control_requests_refuse_bad_arguments(rb):
    from orfa.simctl import SimControlError
    ctl = rb.sim.control
    for bad in ("i2c arb 0 9", "i2c arb 256 0", "i2c glitch start 0 0", "i2c glitch up 1 1",
                "i2c glitch stop 1", "i2c arb x 1"):
        with pytest.raises(SimControlError):
            ctl.request(bad)
    assert ctl.i2c_armed() == "none"
    ctl.i2c_arb(2, 3)
    assert ctl.i2c_armed() == "arb 2 3"
    ctl.i2c_glitch("stop", 1, 8)
    assert ctl.i2c_armed() == "glitch stop 1 8"
    ctl.i2c_disarm()
    assert ctl.i2c_armed() == "none"


# --- a master that is addressed while it loses (0x68, 0xB0) -------------------

ARB_ELF = REPO_ROOT / "build" / "sim-fw" / "twi_arb_master.elf"
ARB = 0x1E          # its TWAR
PORTA = 0x3B        # data addresses on the ATmega32
PORTC = 0x35


@pytest.fixture(scope="module")
def arb_robot():
    """An M32-D gateway, the M128-S slave at 0x10 and, as a second master,
    tests/sim/fw/twi_arb_master.c (an ATmega32 whose TWI answers at 1E)."""
    require_builds(["m32d"])
    if not ARB_ELF.is_file():
        pytest.fail("missing %s: run `make sim`" % ARB_ELF, pytrace=False)
    slaves = [("m128s", M128S, require_slave("m128s", M128S)), ("m32d", ARB, ARB_ELF)]
    sim = SimBoard("m32d", trace=True, control=True, slaves=slaves)
    with running(sim) as b:
        yield b


def test_a_master_addressed_while_it_loses(arb_robot):
    """The second master's TWI (TWEA set, TWAR 1E with TWGCE) loses
    arbitration in its address byte: where the address the devices read is
    its own it is addressed by it, 0xB0 (a read) or 0x68 (a write), 0x78
    when it is the general call, else 0x38; with no fault it is 0x20
    (nobody at 20). The gateway's bus works after each."""
    b = arb_robot
    ctl = b.sim.control
    arb = ctl.slave(ARB)
    for n, (fault, want, seen) in enumerate([("arb 0 2", 0xB0, "1F ack"),
                                              ("arb 0 7", 0x68, "1E ack"),
                                              (None, 0x20, "20 nack"),
                                              ("arb 0 3", 0x38, "0F nack"),
                                              ("arb 0 7", 0x78, "00 ack")], 1):
        mark = b.mark()
        if fault:
            ctl.request("i2c " + fault)
        arb.drive("B0", 0)
        ctl.wait(2 * MS)
        arb.drive("B0", None)
        assert arb.peek(PORTC)[0] == n
        assert arb.peek(PORTA)[0] == want, (fault, hex(arb.peek(PORTA)[0]))
        ev = [(e.kind,) + e.fields for e in b.events(mark, ["twi"])]
        assert ("twi addr",) + tuple(seen.split()) in ev, ev
        if want in (0x68, 0xB0):
            assert ("twi arb-lost", "1E") in ev, ev
        elif want == 0x78:
            assert ("twi arb-lost", "00") in ev, ev
        elif want == 0x38:
            assert ("twi arb-lost",) in ev, ev
        ctl.wait(40 * MS)
        assert ctl.i2c()["sda"] == 1 and ctl.i2c()["scl"] == 1
        assert status(b, M128S) == OK
    # the general call from the gateway: acknowledged (TWGCE), 0x70 then a
    # data byte 0x90, then the STOP
    assert b.ask("S 00 5A P") == b"SWAP\r\n"
    assert arb.peek(PORTA)[0] == 0x90


# --- what a logic analyzer sees ------------------------------------------------

@needs_sigrok
def test_a_logic_analyzer_sees_the_rivals_bit():
    """The rival is on the wire: sigrok's i2c decoder, on the VCD's `sda`
    and `scl`, reads the bytes the devices read (05 with its bit 5 pulled
    low and the rest let go: 03; the address 10 with its bit 3: 0F, a read
    from 07 nobody acknowledges) and nothing else the trace does not say:
    no STOP after either (the gateway abandoned them), the next START
    repeated to the analyzer."""
    require_builds(["m32d"])
    sim = SimBoard("m32d", slaves=[("m128s", M128S, require_slave("m128s", M128S))],
                   control=True, vcd=True, trace=True)

    def talk(port):
        for fault, want in (("i2c arb 3 5", b"ERROR 07"), ("i2c arb 0 3", b"ERROR 06"),
                            (None, b"SWAAAAAAAP")):
            if fault:
                sim.control.request(fault)
            port.write(servo_write(M128S).encode() + b"\r")
            assert port.readline().strip() == want

    run_capture(sim, talk)
    try:
        trace = trace_view(sim.trace_events(kinds=["twi"]))
        decoded = i2c_view(sim.vcd_path)
    finally:
        shutil.rmtree(sim.dir, ignore_errors=True)
    assert decoded == trace
    assert ("DW", 0x03, 1) in decoded and ("AR", 0x0F >> 1, 0) in decoded
    assert decoded.count("P") == 1


# --- a START the lines themselves carry --------------------------------------

def test_a_start_on_the_lines_in_a_byte_is_a_bus_error(rb):
    """A device that pulls SDA low while SCL is high, in the middle of a
    bit the gateway sends high, makes a real START on the lines (no glitch
    involved): the gateway's TWI and the slave's see the bus error as the
    datasheet's TWI detects it (ERROR 07, the write dropped). At the
    slowest clock (C0001, an SCL period of SLOW_P cycles) the pull, timed
    from the end of byte 3 (`wait i2c`), lands in the high half of byte 4's
    bit 1 (DC: a 1) however long the slave stretched before it."""
    b = rb
    ctl = b.sim.control
    req = (servo_write(M128S) + "\n").encode()
    try:
        assert b.ask("C0001") == b"C0000\r\n"
        mark = b.mark()
        # bit 0's SCL rises half a period after byte 3's acknowledge, bit
        # 1's a period later, and falls after another half
        out = ctl.requests(["time", "rx +%d %s" % (LEAD, req.hex().upper()),
                            "wait i2c 4 %d" % (40 * SLOW_P), "wait %d" % (7 * SLOW_P // 4),
                            "i2c stuck 1"])
        assert b.read_lines(1) == b"ERROR 07\r\n"
        waited, pulled = int(out[2]), int(out[3])
        scl = ctl.edges("scl", waited + 1)
        rise = [c for c, lvl in scl if lvl][1]
        fall = next((c for c, lvl in scl if not lvl and c > rise), None)
        assert rise < pulled and (fall is None or pulled < fall), (waited, pulled, scl)
        ev = [(e.kind,) + e.fields for e in b.events(mark, ["twi"])]
        assert ("twi line", "SDA", "0") in ev and ("twi bus-error",) in ev, ev
        assert ("twi bus-error", "%02X" % M128S) in ev and not any(
            e[0] == "twi glitch" for e in ev), ev
        # the device lets go (SCL high: a STOP, after the frame was dropped)
        ctl.i2c_stuck(0)
        assert status(b, M128S) == DROPPED
        applied_nothing(b, M128S, int(out[0]))
    finally:
        ctl.i2c_stuck(0)
        assert b.ask("C0064") == b"C0063\r\n"
