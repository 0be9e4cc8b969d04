"""GPIO driver (docs/registers.md "GPIO"): levels, directions and pull-ups
on the pins, inputs driven from outside, masks, other functions' lines."""

import pytest

BAD_LENGTH = 0x01


def ports(drv):
    return list(enumerate(drv.lay["gpio_ports"]))


def free_mask(drv, port):
    """Lines GPIO holds after reset: all but the fixed functions' lines."""
    return sum(1 << l for l in range(8) if "%s%d" % (port, l) not in drv.lay["fixed_pins"])


def levels(drv, port):
    return drv.read_levels(port)


def fixed_snapshot(drv):
    return {p: drv.pin(p) for p in sorted(drv.lay["fixed_pins"])}


@pytest.mark.parametrize("pattern", [0xA5, 0x5A, 0xFF, 0x00])
def test_outputs(drv, pattern):
    fixed = fixed_snapshot(drv)
    for i, port in ports(drv):
        drv.wr(drv.lay["gpio_mode"] + i, b"\xff")
        drv.wr(drv.lay["gpio_val"] + i, bytes([pattern]))
    for i, port in ports(drv):
        free = free_mask(drv, port)
        for l in range(8):
            if free >> l & 1:
                assert drv.pin("%s%d" % (port, l)) == (pattern >> l & 1, "out"), (port, l)
        assert drv.rd(drv.lay["gpio_val"] + i, 1)[0] == levels(drv, port), port
        assert drv.rd(drv.lay["gpio_mode"] + i, 1)[0] & free == free, port
    assert fixed_snapshot(drv) == fixed


def test_pullups_and_inputs(drv):
    for i, port in ports(drv):
        free = free_mask(drv, port)
        drv.wr(drv.lay["gpio_mode"] + i, b"\x00")
        drv.wr(drv.lay["gpio_val"] + i, b"\x0f")
        for l in range(8):
            if free >> l & 1:
                want = (1, "in pullup") if l < 4 else (0, "in")
                assert drv.pin("%s%d" % (port, l)) == want, (port, l)
        assert drv.rd(drv.lay["gpio_val"] + i, 1)[0] & free == 0x0F & free
        assert drv.rd(drv.lay["gpio_mode"] + i, 1)[0] & free == 0


@pytest.mark.parametrize("pattern", [0x3C, 0xC3, 0x96])
def test_driven_inputs_read_back(drv, pattern):
    for i, port in ports(drv):
        free = free_mask(drv, port)
        drv.wr(drv.lay["gpio_val"] + i, b"\xf0")       # pull-ups on 4-7
        for l in range(8):
            if free >> l & 1:
                drv.drive("%s%d" % (port, l), pattern >> l & 1)
        for l in range(8):
            if free >> l & 1:
                assert drv.pin("%s%d" % (port, l)) == (pattern >> l & 1, "in ext"), (port, l)
        got = drv.rd(drv.lay["gpio_val"] + i, 1)[0]
        assert got & free == pattern & free, (port, hex(got))
        assert got == levels(drv, port)


def test_released_input_follows_the_pullup(drv):
    i, port = ports(drv)[0]
    drv.drive("%s3" % port, 0)
    drv.wr(drv.lay["gpio_val"] + i, b"\x08")
    assert drv.rd(drv.lay["gpio_val"] + i, 1)[0] & 0x08 == 0
    drv.drive("%s3" % port, None)
    assert drv.pin("%s3" % port) == (1, "in pullup")
    assert drv.rd(drv.lay["gpio_val"] + i, 1)[0] & 0x08 == 0x08


def test_masked_writes(drv):
    i, port = ports(drv)[0]                  # port A on both boards: all GPIO
    mode, val = drv.lay["gpio_mode"] + i, drv.lay["gpio_val"] + i
    drv.wr(mode, b"\xff")
    drv.wr(val, b"\x00")
    drv.wr(val, b"\xff\x0f")
    assert levels(drv, port) == 0x0F
    drv.wr(val, b"\x00\x03")
    assert levels(drv, port) == 0x0C
    drv.wr(mode, b"\x00\x30")
    assert drv.rd(mode, 1) == b"\xcf"
    for l in (4, 5):
        assert drv.pin("%s%d" % (port, l)) == (0, "in")
    drv.wr(mode, b"\xff\x00")                # empty mask: nothing changes
    drv.wr(val, b"\xff\x00")
    assert drv.rd(mode, 1) == b"\xcf"
    assert drv.rd(val, 1) == b"\x0c"


def test_manual_f3_example(drv):
    """The manual's example: on a 2-port board write F3 to R+3 (the mode
    register of port F): lines 2 and 3 inputs, the others outputs. On the M32-D the same on port A
    (mode register R+4)."""
    reg = drv.lay["gpio_val"] + (3 if drv.board == "m128s" else 4)
    port = "F" if drv.board == "m128s" else "A"
    drv.wr(reg, b"\xf3")
    assert drv.rd(reg, 1) == b"\xf3"
    for l in range(8):
        want = "in" if l in (2, 3) else "out"
        assert drv.pin("%s%d" % (port, l)) == (0, want), l


def test_other_functions_lines_never_change(drv):
    fixed = fixed_snapshot(drv)
    modes = {i: drv.rd(drv.lay["gpio_mode"] + i, 1)[0] for i, _ in ports(drv)}
    for value in (0xFF, 0x00):
        for i, port in ports(drv):
            drv.wr(drv.lay["gpio_mode"] + i, bytes([value]))
            drv.wr(drv.lay["gpio_val"] + i, bytes([value, 0xFF]))
            got = drv.rd(drv.lay["gpio_mode"] + i, 1)[0]
            free = free_mask(drv, port)
            assert got & ~free & 0xFF == modes[i] & ~free & 0xFF, port
            assert got & free == value & free, port
        assert fixed_snapshot(drv) == fixed


def test_lines_of_a_pulsing_servo_and_an_adc_channel(drv):
    sp = drv.lay["servo"] + 1
    if drv.board == "m32d":
        drv.wr(sp, bytes([8, 0x05, 0xDC]))             # servo 8 = PC7
        servo_pin, sport = "C7", "C"
    else:
        servo_pin, sport = None, None
    # (the servo first: its widths while the ADC converts have their own test)
    if servo_pin:
        t0 = drv.now()
        sidx = drv.lay["gpio_ports"].index(sport)
        for v in (0x00, 0xFF):
            drv.wr(drv.lay["gpio_mode"] + sidx, bytes([v]))
            drv.wr(drv.lay["gpio_val"] + sidx, bytes([v]))
        drv.wait(5 * 147456)
        m = drv.measure(servo_pin, t0)
        assert abs(m["high"][0] - 11059.2) <= 8 and abs(m["high"][1] - 11059.2) <= 8, m
        assert drv.rd(drv.lay["gpio_mode"] + sidx, 1)[0] & 0x80 == 0x80
    drv.wr(drv.lay["adc"], b"\x01\x02")                # ADC 1 (PA1 / PF1)
    adc_pin = drv.lay["adc_port"] + "1"
    aidx = drv.lay["gpio_ports"].index(drv.lay["adc_port"])
    drv.wr(drv.lay["gpio_mode"] + aidx, b"\xff")
    drv.wr(drv.lay["gpio_val"] + aidx, b"\xff")
    assert drv.pin(adc_pin) == (0, "in")
    assert drv.rd(drv.lay["gpio_mode"] + aidx, 1) == b"\xfd"


@pytest.mark.parametrize("length", [3, 4, 8])
def test_bad_length(drv, length):
    for i, port in ports(drv):
        for reg in (drv.lay["gpio_val"] + i, drv.lay["gpio_mode"] + i):
            before = drv.rd(reg, 1)
            drv.wr_refused(reg, bytes([0xFF] * length), BAD_LENGTH)
            assert drv.rd(reg, 1) == before
        free = free_mask(drv, port)
        for l in range(8):
            if free >> l & 1:
                assert drv.pin("%s%d" % (port, l)) == (0, "in"), (port, l)
