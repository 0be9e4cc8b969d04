"""ADC driver (docs/registers.md "ADC"): RC settings and mask, RD values of
the voltages the simulator puts on the analog inputs."""

import pytest

BAD_LENGTH, BAD_VALUE, PIN_BUSY, NOT_WRITABLE = 0x01, 0x02, 0x03, 0x04
#: 10 ms: values valid by then (docs/registers.md, "ADC").
VALID = 73728
#: CPU cycles a conversion: 13 clocks of the ADC's F_CPU / 128 (docs/registers.md).
ADC_CONVERSION = 13 * 128
INPUTS = [0, 250, 1000, 1234, 2000, 2500, 3300, 4999]        # mV on inputs 0-7


def rc(drv):
    return drv.lay["adc"]


def rd_reg(drv):
    return drv.lay["adc"] + 1


def expected(mv, vref):
    return min(1023, round(mv * 1023 / vref))


def set_inputs(drv, values):
    for ch, mv in enumerate(values):
        drv.ctl.adc(ch, mv)


@pytest.fixture
def analog(drv):
    set_inputs(drv, INPUTS)
    drv.ctl.avcc(5000)
    drv.ctl.aref(5000)
    yield drv
    drv.ctl.avcc(5000)
    drv.ctl.aref(5000)


@pytest.mark.parametrize("ref, how, vref", [
    (0, "aref", 4096), (0, "aref", 2500), (1, "avcc", 5000), (1, "avcc", 3300),
    (2, None, 2560), (3, None, 2560),
])
def test_values_for_each_reference(analog, ref, how, vref):
    drv = analog
    if how == "aref":
        drv.ctl.aref(vref)
    elif how == "avcc":
        drv.ctl.avcc(vref)
    for bits10 in (1, 0):
        settings = ref | (bits10 << 2)
        drv.wr(rc(drv), bytes([settings, 0xFF]))
        drv.wait(VALID)
        want = [expected(mv, vref) for mv in INPUTS]
        if bits10:
            data = drv.rd(rd_reg(drv), 16)
            got = [int.from_bytes(data[2 * i:2 * i + 2], "big") for i in range(8)]
            for ch in range(8):
                assert abs(got[ch] - want[ch]) <= 2, (ch, INPUTS[ch], vref, got[ch], want[ch])
        else:
            got = list(drv.rd(rd_reg(drv), 8))
            for ch in range(8):
                assert abs(got[ch] - (want[ch] >> 2)) <= 1, (ch, INPUTS[ch], vref, got[ch], want[ch] >> 2)
        assert drv.rd(rc(drv), 2) == bytes([settings, 0xFF])


def test_channels_off_read_0_and_reading_fewer(analog):
    drv = analog
    drv.wr(rc(drv), bytes([0x05, 0b10100110]))
    drv.wait(VALID)
    data = drv.rd(rd_reg(drv), 16)
    got = [int.from_bytes(data[2 * i:2 * i + 2], "big") for i in range(8)]
    for ch in range(8):
        if 0b10100110 >> ch & 1:
            assert abs(got[ch] - expected(INPUTS[ch], 5000)) <= 2, (ch, got)
        else:
            assert got[ch] == 0, (ch, got)
    assert drv.rd(rd_reg(drv), 3) == data[:3]
    assert drv.rd(rd_reg(drv), 5) == data[:5]
    drv.wr(rc(drv), bytes([0x01, 0b10100110]))
    drv.wait(VALID)
    eight = drv.rd(rd_reg(drv), 8)
    assert drv.rd(rd_reg(drv), 2) == eight[:2]
    assert [eight[ch] for ch in (0, 3, 4, 6)] == [0, 0, 0, 0]


def test_values_follow_the_inputs(analog):
    drv = analog
    drv.wr(rc(drv), bytes([0x05, 0x01]))
    for mv in (0, 1500, 3000, 4500, 5000):
        drv.ctl.adc(0, mv)
        drv.wait(VALID)
        got = int.from_bytes(drv.rd(rd_reg(drv), 2), "big")
        assert abs(got - expected(mv, 5000)) <= 2, (mv, got)


def test_a_reading_is_at_most_a_round_and_a_conversion_old(analog):
    """docs/registers.md, "ADC": 1664 cycles a conversion, every one of the 8
    channels refreshed within 8 x 1664 cycles; a change on any input shows
    within a round and the conversion under way (the read's request comes on
    top)."""
    drv = analog
    drv.wr(rc(drv), bytes([0x05, 0xFF]))
    drv.wait(VALID)
    for ch, mv in ((7, 1000), (0, 4000), (3, 2222)):
        drv.ctl.adc(ch, mv)
        drv.wait(9 * ADC_CONVERSION)
        data = drv.rd(rd_reg(drv), 16)
        got = int.from_bytes(data[2 * ch:2 * ch + 2], "big")
        assert abs(got - expected(mv, 5000)) <= 2, (ch, mv, got)


def test_enabled_lines_are_taken_from_gpio(analog):
    drv = analog
    port = drv.lay["adc_port"]
    pidx = drv.lay["gpio_ports"].index(port)
    mode, val = drv.lay["gpio_mode"] + pidx, drv.lay["gpio_val"] + pidx
    drv.wr(mode, b"\xff")
    drv.wr(val, b"\x55")                       # lines 0 2 4 6 high outputs
    drv.wr(rc(drv), bytes([0x01, 0x0F]))       # channels 0-3 become the ADC's
    for line in range(4):
        assert drv.pin("%s%d" % (port, line)) == (0, "in"), line      # no pull-up
    for line in range(4, 8):
        assert drv.pin("%s%d" % (port, line)) == (line % 2 == 0 and 1 or 0, "out"), line
    assert drv.rd(mode, 1) == b"\xf0"
    drv.wr(mode, b"\xff")                      # skipped for the ADC's lines
    drv.wr(val, b"\xff")
    for line in range(4):
        assert drv.pin("%s%d" % (port, line)) == (0, "in"), line
    assert drv.rd(mode, 1) == b"\xf0"
    drv.wait(VALID)
    data = drv.rd(rd_reg(drv), 1)
    assert data == bytes([expected(INPUTS[0], 5000) >> 2])
    drv.wr(rc(drv), bytes([0x01, 0x00]))       # given back to GPIO: inputs
    assert drv.rd(mode, 1) == b"\xf0"
    for line in range(4):
        assert drv.pin("%s%d" % (port, line))[1].startswith("in"), line


@pytest.mark.parametrize("reg_off, data, status", [
    (0, "08FF", BAD_VALUE), (0, "80FF", BAD_VALUE), (0, "FF01", BAD_VALUE),
    (0, "05", BAD_LENGTH), (0, "05FF00", BAD_LENGTH),
    (1, "00", NOT_WRITABLE), (1, "0000", NOT_WRITABLE),
])
def test_rejected_writes(analog, reg_off, data, status):
    drv = analog
    drv.wr(rc(drv), bytes([0x05, 0x03]))
    drv.wait(VALID)
    before = drv.rd(rd_reg(drv), 16)
    drv.wr_refused(drv.lay["adc"] + reg_off, bytes.fromhex(data), status)
    assert drv.rd(rc(drv), 2) == b"\x05\x03"
    drv.wait(VALID)
    assert drv.rd(rd_reg(drv), 16) == before
    port = drv.lay["adc_port"]
    for line in range(2, 8):
        assert drv.pin("%s%d" % (port, line)) == (0, "in")


def test_line_of_another_function_refuses_the_whole_write(analog):
    drv = analog
    if drv.board == "m32d":
        drv.wr(drv.lay["servo"] + 1, bytes([5, 0x05, 0xDC]))       # servo 5 = PA5
    else:
        drv.wr(drv.lay["spi"] + 1, bytes([0, 1, 5]))               # SPI CS on PF5
    drv.wr_refused(rc(drv), bytes([0x05, 0x21]), PIN_BUSY)
    assert drv.rd(rc(drv), 2) == b"\x00\x00"
    drv.wait(VALID)
    assert drv.rd(rd_reg(drv), 16) == bytes(16)
    port = drv.lay["adc_port"]
    assert drv.pin("%s0" % port) == (0, "in")
    if drv.board == "m128s":
        assert drv.pin("F5") == (1, "out")
        # put the chip select back on a line no other test module needs
        drv.wr(drv.lay["spi"] + 1, bytes([0, 0, 7]))
