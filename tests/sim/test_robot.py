"""A robot on one simulated I2C bus (docs/registers.md "On a
slave board"): an M32-D gateway on the PC's serial port, an M128-S slave at
0x10, an M32-D slave at 0x12, a 24C02 EEPROM at 0xA0 and an SRF08 ranger at
0xE0. Everything goes through the gateway's serial port as a PC would; the
slaves' pins are watched through the control socket (`10/servo3`, `12/A5`)."""

import pytest

from conftest import (F_CPU, SERVO_FRAME, REPLY_TIMEOUT, DrvBench, require_builds,
                      require_slave, running)
from orfa.sim import SimBoard
from orfa.simctl import SimControlError

M128S, M32D = 0x10, 0x12
EEPROM, SRF08 = 0xA0, 0xE0
OK, BAD_LENGTH, BAD_VALUE, NOT_WRITABLE, NOT_READABLE, NO_REGISTER = 0, 1, 2, 4, 5, 8
#: docs/registers.md: the records of each board's drivers.
COUNT = {M128S: 6, M32D: 7}


@pytest.fixture(scope="module")
def robot():
    require_builds(["m32d"])
    slaves = [("m128s", M128S, require_slave("m128s", M128S)),
              ("m32d", M32D, require_slave("m32d", M32D))]
    sim = SimBoard("m32d", eeproms=(EEPROM,), srf08=(SRF08,), trace=True, control=True,
                   slaves=slaves)
    with running(sim) as gw:
        boards = {M128S: DrvBench(sim, "m128s", M128S, gw=gw.gw),
                  M32D: DrvBench(sim, "m32d", M32D, gw=gw.gw)}
        yield gw, boards


@pytest.fixture
def rb(robot):
    gw, boards = robot
    assert gw.sim.running, gw.sim.stderr
    gw.gw.reset_input_buffer()
    mark = gw.mark()
    yield gw, boards
    gw.restore()
    assert gw.events(mark, ["reset"]) == []


def ask(gw, req):
    return gw.ask(req)


# --- introspection and status through the bus ---------------------------------

@pytest.mark.parametrize("addr", [M128S, M32D])
def test_slave_introspection(rb, addr):
    gw, _ = rb
    n = COUNT[addr]
    w, r = addr, addr | 1
    assert ask(gw, "S %02X 00 00 S %02X 01 P" % (w, r)) == b"SWAASR%02XP\r\n" % n
    # reading the count moves nothing: again, and in every byte of a longer read
    assert ask(gw, "S %02X 01 P" % r) == b"SR%02XP\r\n" % n
    assert ask(gw, "S %02X 03 P" % r) == b"SR%02X%02X%02XP\r\n" % (n, n, n)
    assert ask(gw, "S %02X 00 01 S %02X 06 P" % (w, r)) == b"SWAASR000001000002P\r\n"
    # all records in one read, then driver 1 again, status 06 (wrapped)
    one = ask(gw, "S %02X 00 01 S %02X %02X P" % (w, r, 6 * n))
    assert one.startswith(b"SWAASR000001000002") and len(one) == 6 + 12 * n + 3
    again = ask(gw, "S %02X 00 01 S %02X %02X P" % (w, r, 6 * (n + 1)))
    assert again == one[:-3] + b"000001000002P\r\n"
    assert ask(gw, "S %02X 01 S %02X 01 P" % (w, r)) == b"SWASR06P\r\n"


def test_slave_records_are_the_boards(rb):
    gw, boards = rb
    for addr, b in boards.items():
        local = ask(gw, "S AA 00 01 S AB 24 P")             # the gateway: an M32-D
        remote = ask(gw, "S %02X 00 01 S %02X 24 P" % (addr, addr | 1))
        if b.board == "m32d":
            assert remote == local
        else:
            assert remote[:6 + 12 * 5] == (b"SWAASR000001000002" b"002101010204"
                                           b"000101010602" b"004001010802" b"003002000A02")


# --- on a slave board: what the slave can and cannot refuse ----------------------

@pytest.mark.parametrize("addr", [M128S, M32D])
def test_unmapped_register(rb, addr):
    gw, boards = rb
    b = boards[addr]
    n = COUNT[addr]
    last = b.record(n)
    free = last[4] + last[5]
    mark = gw.mark()
    # the register byte is acknowledged (the TWI decides first), the byte
    # after it is not: ERROR 07
    assert ask(gw, "S %02X %02X 00 P" % (addr, free)) == b"ERROR 07\r\n"
    bus = gw.bus(mark)
    assert bus[:3] == [("start",), ("addr", "%02X" % addr, "ack"), ("write", "%02X" % free, "ack")]
    assert bus[3] == ("write", "00", "nack")
    assert b.status() == NO_REGISTER
    # a frame that ends right after it is acknowledged in full; the status tells
    assert ask(gw, "S %02X 00 01 S %02X 06 P" % (addr, addr | 1)).startswith(b"SWAASR0000")
    assert b.status() == OK
    assert ask(gw, "S %02X %02X P" % (addr, free)) == b"SWAP\r\n"
    assert b.status() == NO_REGISTER


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_status_register_refuses_data(rb, addr):
    gw, boards = rb
    # the first data byte is acknowledged, the second is not
    assert ask(gw, "S %02X 01 00 P" % addr) == b"SWAAP\r\n"
    assert boards[addr].status() == NOT_WRITABLE
    assert ask(gw, "S %02X 01 00 00 P" % addr) == b"ERROR 07\r\n"
    assert boards[addr].status() == NOT_WRITABLE


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_data_byte_that_makes_the_write_invalid(rb, addr):
    """On a slave board: the byte after it is not acknowledged (ERROR 07); a frame that
    ends with it is acknowledged in full; the status tells either way and
    nothing is applied."""
    gw, boards = rb
    b = boards[addr]
    sp = b.lay["servo"] + 1
    ch = b.lay["servo_channels"]                 # no such channel
    mark = gw.mark()
    assert ask(gw, "S %02X %02X %02X 05 DC P" % (addr, sp, ch)) == b"ERROR 07\r\n"
    assert gw.bus(mark)[2:5] == [("write", "%02X" % sp, "ack"), ("write", "%02X" % ch, "ack"),
                                 ("write", "05", "nack")]
    assert b.status() == BAD_VALUE
    assert b.rd(sp, 2) == b"\x00\x00"            # nothing applied
    # the same channel byte last: acknowledged, refused at the end
    assert ask(gw, "S %02X %02X %02X P" % (addr, sp, ch)) == b"SWAAP\r\n"
    assert b.status() == BAD_VALUE
    # introspection takes one byte: the second is refused, the third NACKed
    assert ask(gw, "S %02X 00 01 02 03 P" % addr) == b"ERROR 07\r\n"
    assert b.status() == BAD_LENGTH
    assert ask(gw, "S %02X 00 01 02 P" % addr) == b"SWAAAP\r\n"
    assert b.status() == BAD_LENGTH
    # an ADC result register cannot be written: its first data byte is refused
    assert ask(gw, "S %02X %02X 00 00 P" % (addr, b.lay["adc"] + 1)) == b"ERROR 07\r\n"
    assert b.status() == NOT_WRITABLE


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_write_rejected_at_frame_end(rb, addr):
    """What only the whole write shows (a length that is not a multiple of
    3) is found when the frame ends: every byte acknowledged, status tells."""
    gw, boards = rb
    b = boards[addr]
    sp = b.lay["servo"] + 1
    assert ask(gw, "S %02X %02X 00 05 P" % (addr, sp)) == b"SWAAAP\r\n"
    assert b.status() == BAD_LENGTH
    assert ask(gw, "S %02X %02X 00 05 DC 01 P" % (addr, sp)) == b"SWAAAAAP\r\n"
    assert b.status() == BAD_LENGTH
    assert b.rd(sp, 2) == b"\x00\x00"


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_read_after_an_unmapped_register_gives_ff(rb, addr):
    """No register is selected after an unmapped one: a read in the same
    request gives FF (the read address is acknowledged), the status keeps 08."""
    gw, _ = rb
    assert ask(gw, "S %02X 03 S %02X 01 P" % (addr, addr | 1))[:5] == b"SWASR"
    assert ask(gw, "S %02X FE S %02X 02 P" % (addr, addr | 1)) == b"SWASRFFFFP\r\n"
    assert ask(gw, "S %02X 01 S %02X 01 P" % (addr, addr | 1)) == b"SWASR08P\r\n"


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_unreadable_register_reads_ff(rb, addr):
    gw, boards = rb
    b = boards[addr]
    # SPI DATA before any exchange cannot be read: the read address is
    # acknowledged anyway, FF bytes, status 05
    assert ask(gw, "S %02X %02X S %02X 03 P" % (addr, b.lay["spi"], addr | 1)) == \
        b"SWASRFFFFFFP\r\n"
    assert b.status() == NOT_READABLE


def test_longest_write_a_gateway_can_send(rb):
    """A request holds 128 characters: 61 data bytes after the register, all
    within the slave's 64-byte buffer (more is refused: tests/unit)."""
    gw, boards = rb
    b = boards[M128S]
    reg = b.lay["servo"]                          # RS: takes anything (driver 1.0)
    body = "00" * 61
    req = "S%02X%02X%sP" % (M128S, reg, body)
    assert len(req) == 128
    assert ask(gw, req) == b"SW" + b"A" * 62 + b"P\r\n"
    assert b.status() == OK
    # on SP the 49th byte is one too many for 16 triples: refused, the 50th NACKed
    assert ask(gw, "S%02X%02X%sP" % (M128S, reg + 1, body)) == b"ERROR 07\r\n"
    assert b.status() == BAD_LENGTH


def test_absent_address(rb):
    gw, _ = rb
    mark = gw.mark()
    assert ask(gw, "S 14 00 P") == b"ERROR 06\r\n"
    assert ask(gw, "S 15 01 P") == b"ERROR 06\r\n"
    assert gw.bus(mark)[:2] == [("start",), ("addr", "14", "nack")]


# --- several devices in one request ----------------------------------------------

def multi_start(gw):
    gw.eeprom_write(0x20, b"\x11\x22")
    req = ("S 10 00 00 S 11 01 S 12 00 00 S 13 01 S A0 20 S A1 02 S 10 00 01 S 11 06 P")
    want = b"SWAASR06SWAASR07SWASR1122SWAASR000001000002P\r\n"
    assert ask(gw, req) == want


def test_multi_start_across_two_slaves_and_the_eeprom(rb):
    gw, _ = rb
    mark = gw.mark()
    multi_start(gw)
    bus = gw.bus(mark)
    assert [e for e in bus if e[0] in ("start", "stop")].count(("stop",)) == 2  # eeprom write + request


@pytest.mark.parametrize("khz, reply", [(400, b"C0170\r\n"), (100, b"C0063\r\n")])
def test_multi_start_at_bus_clock(rb, khz, reply):
    gw, _ = rb
    assert ask(gw, "C %04X" % khz) == reply
    mark = gw.mark()
    multi_start(gw)
    ev = gw.events(mark, ["twi"])
    start = [e.cycle for e in ev if e.kind == "twi start"]
    stop = [e.cycle for e in ev if e.kind == "twi stop"]
    assert start and stop
    # the request's transfer: 8 frames, 25 bytes of 9 clocks each
    span = stop[-1] - start[1]
    period = F_CPU / (khz * 1000)
    assert 25 * 9 * period <= span, span


def test_pipelined_requests_to_slaves_all_answered_in_order(rb):
    gw, boards = rb
    reqs, want = [], []
    for i in range(150):
        addr = (M128S, M32D)[i % 2]
        if i % 3 == 0:
            reqs.append(b"S %02X 00 00 S %02X 01 P" % (addr, addr | 1))
            want.append(b"SWAASR%02XP\r\n" % COUNT[addr])
        elif i % 3 == 1:
            reqs.append(b"S %02X 00 01 S %02X 06 P" % (addr, addr | 1))
            want.append(b"SWAASR000001000002P\r\n")
        else:
            reqs.append(b"V")
            want.append(b"V1.1\r\n")
    # in windows the size the flow rule (docs/protocol.md) allows (< 256
    # characters pending)
    got = []
    for i in range(0, len(reqs), 8):
        chunk = reqs[i:i + 8]
        gw.gw.send(b"".join(r + b"\n" for r in chunk))
        got.append(gw.read_lines(len(chunk), timeout=4 * REPLY_TIMEOUT))
    assert b"".join(got) == b"".join(want)


# --- pins of the slaves ------------------------------------------------------------

def test_m128s_slave_servo_on_its_4017_output(rb):
    gw, boards = rb
    b = boards[M128S]
    sp = b.lay["servo"] + 1
    b.wr(sp, bytes([3, 1500 >> 8, 1500 & 0xFF, 17, 900 >> 8, 900 & 0xFF]))
    try:
        b.wait(3 * SERVO_FRAME)
        t = b.now()
        b.wait(10 * SERVO_FRAME)
        for ch, us in ((3, 1500), (17, 900)):
            m = b.measure("servo%d" % ch, t, 8)
            lo, hi, _ = m["high"]
            assert abs(lo / F_CPU * 1e6 - us) <= 1.1 and abs(hi / F_CPU * 1e6 - us) <= 1.1, (ch, m)
            plo, phi, _ = m["period"]
            assert abs(plo - SERVO_FRAME) <= 147 and abs(phi - SERVO_FRAME) <= 147, (ch, m)
        assert b.ctl.level("servo4") == 0
    finally:
        b.servos_off()


def test_slave_servos_while_the_bus_streams_requests(rb):
    """Servo widths on a slave stay within 1.1 us while it answers a stream
    of requests (its TWI interrupt and SCL stretching are short)."""
    gw, boards = rb
    for addr in (M128S, M32D):
        b = boards[addr]
        sp = b.lay["servo"] + 1
        b.wr(sp, bytes([2, 1234 >> 8, 1234 & 0xFF, 5, 2000 >> 8, 2000 & 0xFF]))
    try:
        gw.sim.control.wait(3 * SERVO_FRAME)
        t = gw.sim.control.time()
        reqs = []
        for i in range(40):
            addr = (M128S, M32D)[i % 2]
            reqs.append(b"S %02X 00 01 S %02X 0C P" % (addr, addr | 1))
        for i in range(0, len(reqs), 6):
            chunk = reqs[i:i + 6]
            gw.gw.send(b"".join(r + b"\n" for r in chunk))
            gw.read_lines(len(chunk), timeout=4 * REPLY_TIMEOUT)
        for addr in (M128S, M32D):
            b = boards[addr]
            for ch, us in ((2, 1234), (5, 2000)):
                # `servo<n>` on both boards; on the M32-D it follows the pin
                sig = "servo%d" % ch
                until = b.now()
                pulses = b.highs(sig, t, until)
                if b.board == "m32d":
                    pin = b.highs(b.lay["servo_pins"][ch], t, until)
                    assert [p[:2] for p in pulses] == [p[:2] for p in pin]
                assert len(pulses) >= 5, (addr, ch, pulses)
                for _, high, _ in pulses:
                    assert abs(high / F_CPU * 1e6 - us) <= 1.1, (addr, ch, high)
    finally:
        for addr in (M128S, M32D):
            boards[addr].servos_off()


def test_m32d_slave_motor_duty(rb):
    gw, boards = rb
    b = boards[M32D]
    b.wr(b.lay["motor"], bytes([0x40, 0xC0, 1, 0]))
    try:
        b.wait(10000)
        t = b.now()
        b.wait(20 * 369)
        m1, m2 = b.measure("D5", t, 10), b.measure("D4", t, 10)
        assert abs(m1["duty"] - 0x40 / 255) < 1 / 368 + 0.01, m1
        assert abs(m2["duty"] - 0xC0 / 255) < 1 / 368 + 0.01, m2
        assert b.ctl.level("B0") == 1 and b.ctl.level("B1") == 0     # DIR1, DIR2
        # the gateway's own motor pins stay quiet
        assert gw.sim.control.measure("D5", t, 10) == {"steady": 0}
    finally:
        b.wr(b.lay["motor"], b"\x00\x00\x00\x00")


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_slave_adc_reads_an_injected_voltage(rb, addr):
    gw, boards = rb
    b = boards[addr]
    b.ctl.avcc(5000)
    # the analog input by its pin, with the slave's prefix: `adc 12/A3 2500`
    b.ctl.adc("%s3" % b.lay["adc_port"], 2500)
    assert b.ctl.request("adc %02X/3" % addr) == "2500"
    b.wr(b.lay["adc"], bytes([0x05, 0x08]))           # AVCC, 10-bit, channel 3
    try:
        b.wait(73728)
        got = b.rd(b.lay["adc"] + 1, 8)
        v = int.from_bytes(got[6:8], "big")
        assert abs(v - 511) <= 2, got.hex()
        assert got[:6] == bytes(6)
    finally:
        b.wr(b.lay["adc"], b"\x00\x00")


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_slave_gpio_levels(rb, addr):
    gw, boards = rb
    b = boards[addr]
    port = b.lay["gpio_ports"][0]                      # A
    b.wr(b.lay["gpio_mode"], bytes([0xF0, 0xFF]))      # A4-A7 out
    b.wr(b.lay["gpio_val"], bytes([0xA0, 0xFF]))
    try:
        assert [b.ctl.level("%s%d" % (port, i)) for i in range(4, 8)] == [0, 1, 0, 1]
        b.drive("%s1" % port, 1)
        b.drive("%s2" % port, 0)
        v = b.rd(b.lay["gpio_val"], 1)[0]
        assert v & 0x06 == 0x02 and v & 0xF0 == 0xA0, hex(v)
    finally:
        b.drv_restore()


# --- the sensor part on the robot's bus -------------------------------------------

def test_srf08_on_the_robot_bus(rb):
    gw, _ = rb
    ctl = gw.sim.control
    ctl.srf08_range(SRF08, 1234)
    assert ask(gw, "S E0 00 51 P") == b"SWAAP\r\n"
    ctl.wait(int(0.066 * F_CPU))
    assert ask(gw, "S E0 02 S E1 02 P") == b"SWASR007BP\r\n"         # 123 cm


# --- clock stretching: measured and bounded --------------------------------------

#: A slave holds SCL while its main loop fetches a driver's read answer
#: (i2c_slave/): about 400 cycles at most (make bench), bounded here with room.
STRETCH_PER_BYTE_MAX = 1000
#: The boards' clock tick (Timer2's wrap), cycles; every board's clock runs
#: from its start-up, at a fixed world cycle.
TICK = 2048
#: The gateway waits more than 34 clock ticks of 2048 cycles (9.4 ms) for a
#: stretching slave (firmware/twi_master.c TWI_WAIT_TICKS), less than 10 ms.
GATEWAY_STRETCH_WAIT = 34 * TICK
#: The longest write's stretch must stay a tick (2048 cycles) short of that:
#: 60886-62672 cycles measured on the M32-D over a servo frame's phases and
#: the frame's place among the clock's ticks (docs/protocol.md).
SLAVE_WRITE_STRETCH_MAX = GATEWAY_STRETCH_WAIT - TICK


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_stretch_per_byte_is_short(rb, addr):
    gw, _ = rb
    mark = gw.mark()
    for _ in range(5):
        assert ask(gw, "S %02X 00 01 S %02X 0C P" % (addr, addr | 1)).startswith(b"SWAASR")
        assert ask(gw, "S %02X 00 00 S %02X 01 P" % (addr, addr | 1)).startswith(b"SWAASR")
    stretches = [n for _, a, n in gw.sim.stretches(mark) if a == addr]
    assert stretches, "the slave never held SCL"       # it does, reading a driver
    assert max(stretches) <= STRETCH_PER_BYTE_MAX, stretches


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_longest_write_stretches_within_the_gateways_wait(rb, addr):
    """16 servo triples, then at once a read back: the slave holds SCL
    until its driver took the write; the gateway waits it out."""
    gw, boards = rb
    b = boards[addr]
    sp = b.lay["servo"] + 1
    chans = [2 * k if b.board == "m128s" else k for k in range(16)]
    body = "".join("%02X%04X" % (ch, 2500 - 37 * k) for k, ch in enumerate(chans))
    mark = gw.mark()
    try:
        reply = ask(gw, "S%02X%02X%sS%02X02P" % (addr, sp, body, addr | 1))
        assert reply == b"SW" + b"A" * 49 + b"SR09C4P\r\n"
        longest = max(n for _, a, n in gw.sim.stretches(mark) if a == addr)
        assert STRETCH_PER_BYTE_MAX < longest < GATEWAY_STRETCH_WAIT, longest
    finally:
        b.servos_off()


#: Where in the servo frame (cycles after a rise of the first pulsing
#: channel) the longest write's request starts: 32 phases across the frame.
WRITE_PHASES = [k * SERVO_FRAME // 32 for k in range(32)]
#: The longest an SPI exchange's clock may stand still between two bytes,
#: cycles: ~90 when nothing comes between, and the M32-D servo interrupt's
#: ~150-210 from its last look at the exchange to the edge (drivers/servo_pins.c).
SPI_IDLE_MAX = 400


def schedule(ctl, requests, first_at):
    """Each of `requests` [(cycle offset, bytes)] on the gateway's serial
    line with `rx` at first_at + offset, first_at moved on by whole servo
    frames should the simulation have passed it; [(start, end)] cycles."""
    while True:
        try:
            return [(first_at + off, ctl.rx(first_at + off, req)) for off, req in requests]
        except SimControlError as e:
            if "is past" not in str(e):
                raise
            first_at += SERVO_FRAME * (1 + (ctl.time() - first_at) // SERVO_FRAME)


@pytest.mark.parametrize("addr", [M128S, M32D])
def test_longest_slave_write_is_waited_for(rb, addr):
    """The slave's longest write: an SPI exchange of as many bytes as a
    request can carry with a read after it (57), at the slowest SPI clock
    (F_CPU/128), with servos pulsing; the read right after waits for it, and
    the gateway waits the stretch out. The servo interrupts take cycles from
    the exchange, how many depends on where in the servo frame it falls and
    where the frame falls among the clock's ticks: the servos start and the
    requests come with `rx` at fixed cycles of both (32 phases across the
    frame), so the test measures the same stretches in every run (within
    ~100 cycles), whatever the machine's load."""
    gw, boards = rb
    b = boards[addr]
    ctl = gw.sim.control
    spi = b.lay["spi"]
    chans = [2 * k if b.board == "m128s" else k for k in range(4, 12)]
    cs = "A3" if b.board == "m128s" else "C2"        # lines no other test here uses
    port, line = b.lay["gpio_ports"].index(cs[0]), int(cs[1])
    try:
        b.wr(spi + 1, bytes([0x00, port, line]))          # channel 0's chip select
        b.wr(spi + 1, bytes([0xFF, 0x00, 0x06]))          # F_CPU/128, mode 0
        # the servos start with a request at the start of a clock tick, so the
        # frame's place among the boards' ticks is the same in every run
        servos = "S%s%02X%sP\n" % (b.wa, b.lay["servo"] + 1,
                                   "".join("%02X05DC" % ch for ch in chans))
        schedule(ctl, [(0, servos.encode())], (ctl.time() // TICK + 64) * TICK)
        assert gw.read_lines(1) == b"SW" + b"A" * (1 + 3 * len(chans)) + b"P\r\n"
        assert b.status() == OK
        t = b.now()
        b.wait(2 * SERVO_FRAME)
        rise = [c for c, level in b.edges(b.lay["servo_pins"][chans[0]], t) if level][-1]
        n = 57                                           # all a request holds with the read
        req = "S%02X%02X00%sS%02X01P" % (addr, spi, "A5" * n, addr | 1)
        assert len(req) == 127                           # one more byte is two more
        mark = gw.mark()
        # two frames apart: each is answered before the next arrives
        first = rise + SERVO_FRAME * (2 + (b.now() - rise) // SERVO_FRAME)
        windows = schedule(ctl, [(2 * SERVO_FRAME * k + phase, req.encode() + b"\n")
                                 for k, phase in enumerate(WRITE_PHASES)], first)
        replies = gw.read_lines(len(windows), 4 * REPLY_TIMEOUT).splitlines(keepends=True)
        stretches = gw.sim.stretches(mark)
        longest = []
        for (start, end), reply in zip(windows, replies):
            assert reply[:2 + n + 2] == b"SW" + b"A" * (n + 2) and reply[n + 4:n + 6] == b"SR", \
                reply
            assert len(reply) == n + 11 and reply[-3:] == b"P\r\n", reply
            longest.append(max(c for at, a, c in stretches
                               if a == addr and end < at < start + 2 * SERVO_FRAME))
        assert all(57 * 1024 < c < SLAVE_WRITE_STRETCH_MAX for c in longest), longest
        # The last exchange's clock (its edges are the last on SCK): between
        # two bytes it stands still ~90 cycles, longer where an interrupt
        # came as a byte ended; the M32-D's servo interrupt moves it on
        # while it waits for an edge (it stood still up to ~730 cycles).
        sck = [c for c, _ in b.edges(b.lay["spi_pins"]["SCK"], windows[-1][1])]
        assert len(sck) == 16 * n, len(sck)
        idle = [sck[i] - sck[i - 1] for i in range(16, len(sck), 16)]
        assert max(idle) < SPI_IDLE_MAX, idle
    finally:
        b.servos_off()
        b.wr(spi + 1, b"\xff\x00\x02")
