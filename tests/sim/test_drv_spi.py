"""SPI driver (docs/registers.md "SPI") against the simulator's SPI devices
(docs/simulator.md): eeprom25 parts in each SPI mode, one LSB-first part and
an mcp3008, each on its own chip-select line."""

import pytest

BAD_LENGTH, BAD_VALUE, PIN_BUSY, NOT_BOUND = 0x01, 0x02, 0x03, 0x07
WIP = 36864 + 2000                 # eeprom25 write cycle: 5 ms

#: chip-select pins: eeprom25 in modes 0-3, eeprom25 LSB first, mcp3008
DEV_PINS = {"m32d": ["C2", "C3", "D2", "D3", "D6", "D7"],
            "m128s": ["A0", "A1", "A2", "A3", "A4", "A5"]}
DRV_SIM_OPTIONS = {
    board: {"spi": ["eeprom25@%s:mode=0" % p[0], "eeprom25@%s:mode=1" % p[1],
                    "eeprom25@%s:mode=2" % p[2], "eeprom25@%s:mode=3" % p[3],
                    "eeprom25@%s:lsb" % p[4], "mcp3008@%s" % p[5]]}
    for board, p in DEV_PINS.items()
}


def port_line(drv, pin):
    return drv.lay["gpio_ports"].index(pin[0]), int(pin[1])


def data_reg(drv):
    return drv.lay["spi"]


def cfg_reg(drv):
    return drv.lay["spi"] + 1


def bind(drv, ch, pin):
    port, line = port_line(drv, pin)
    drv.wr(cfg_reg(drv), bytes([ch, port, line]))


def pullups(drv):
    """Pull-ups on every device's chip-select line that GPIO holds, as a
    board's resistors would: a floating line reads 0 in the simulator and
    would select its device (GPIO lines are inputs without pull-up)."""
    for port in sorted({p[0] for p in DEV_PINS[drv.board]}):
        mask = sum(1 << int(p[1]) for p in DEV_PINS[drv.board] if p[0] == port)
        drv.wr(drv.lay["gpio_val"] + drv.lay["gpio_ports"].index(port), bytes([mask, mask]))


@pytest.fixture
def spi(drv):
    """Channels 0-3 on the eeprom25 of modes 0-3 (home), before and after."""
    pins = DEV_PINS[drv.board]
    pullups(drv)
    for ch in range(4):
        bind(drv, ch, pins[ch])
    drv.ctl.spi()                                   # forget earlier exchanges
    yield drv
    drv.settle()
    drv.wr(cfg_reg(drv), b"\xff\x00\x02")
    for ch in range(4):
        bind(drv, ch, pins[ch])


def bus(drv, div=2, mode=0, lsb=False):
    drv.wr(cfg_reg(drv), bytes([0xFF, 0x00, div | mode << 3 | (0x20 if lsb else 0)]))


def xfer(drv, ch, data):
    """DATA write, then the bytes received, read back through DATA."""
    drv.wr(data_reg(drv), bytes([ch]) + bytes(data))
    return drv.rd(data_reg(drv), len(data))


def eeprom_write(drv, ch, addr, data):
    xfer(drv, ch, b"\x06")
    xfer(drv, ch, bytes([0x02, addr]) + bytes(data))
    drv.wait(WIP)


def eeprom_read(drv, ch, addr, n):
    return xfer(drv, ch, bytes([0x03, addr]) + bytes(n))


def shifted(raw):
    """What a master sampling one edge early sees (CPHA mismatch)."""
    out, prev = [], 1
    for b in raw:
        out.append((prev << 7 | b >> 1) & 0xFF)
        prev = b & 1
    return bytes(out)


def rev(b):
    return int("{:08b}".format(b)[::-1], 2)


def test_config_read_back(spi):
    drv = spi
    pins = DEV_PINS[drv.board]
    want = b"\x02" + b"".join(bytes(port_line(drv, pins[ch])) for ch in range(4))
    assert drv.rd(cfg_reg(drv), 9) == want
    for ch in range(4):
        assert drv.pin(pins[ch]) == (1, "out"), ch     # deselected
    bus(drv, 5, 3, True)
    assert drv.rd(cfg_reg(drv), 9) == bytes([0x3D]) + want[1:]
    assert drv.rd(cfg_reg(drv), 1) == b"\x3d"


@pytest.mark.parametrize("mode", [0, 1, 2, 3])
def test_eeprom_in_each_mode(spi, mode):
    drv = spi
    pin = DEV_PINS[drv.board][mode]
    bus(drv, 2, mode)
    data = bytes([0x10 * mode + i for i in range(1, 7)])
    addr = 0x20 + 8 * mode
    eeprom_write(drv, mode, addr, data)
    assert data.hex().upper() in drv.ctl.spidev(pin).split()[-1][2 * addr:2 * addr + 12].upper()
    drv.ctl.spi()
    got = eeprom_read(drv, mode, addr, 6)
    assert got[2:] == data and got[:2] == b"\xff\xff", got
    log = drv.ctl.spi()
    assert log == [{"cs": pin, "mosi": bytes([3, addr]) + bytes(6), "miso": got}], log
    # RDSR: write enable latch cleared after the write
    assert xfer(drv, mode, b"\x05\x00")[1] & 0x03 == 0


@pytest.mark.parametrize("mode", [0, 1, 2, 3])
def test_chip_select_only_around_the_exchange(spi, mode):
    drv = spi
    pin = DEV_PINS[drv.board][mode]
    sck, mosi = drv.lay["spi_pins"]["SCK"], drv.lay["spi_pins"]["MOSI"]
    bus(drv, 2, mode)
    assert drv.pin(sck) == (mode >> 1, "out spi")           # idles at CPOL
    t0 = drv.now()
    drv.ctl.spi()
    drv.wr(data_reg(drv), bytes([mode, 0x03, 0x00, 0xA5, 0x5A]))
    drv.wait(1000)
    assert [x["cs"] for x in drv.ctl.spi()] == [pin]       # one device selected
    cs = drv.edges(pin, t0)
    assert [l for _, l in cs] == [0, 1], cs
    fall, rise = cs[0][0], cs[1][0]
    clk = drv.edges(sck, t0)
    assert len(clk) == 4 * 16, len(clk)
    assert fall < clk[0][0] and clk[-1][0] < rise, (cs, clk[0], clk[-1])
    for c, _ in drv.edges(mosi, t0):
        assert fall <= c <= rise
    assert clk[-1][1] == mode >> 1                          # back to idle
    for other in DEV_PINS[drv.board][:4]:
        if other != pin:
            assert drv.edges(other, t0) == [], other


@pytest.mark.parametrize("div", range(7))
def test_clock_divider(spi, div):
    drv = spi
    sck = drv.lay["spi_pins"]["SCK"]
    bus(drv, div, 0)
    t0 = drv.now()
    drv.wr(data_reg(drv), bytes([0, 0x05, 0x00, 0x00]))
    drv.wait(8 * 1024)
    edges = drv.edges(sck, t0)
    assert len(edges) == 3 * 16
    half = 2 ** div                   # SCK = F_CPU / 2^(div+1)
    for b in range(3):
        byte = edges[16 * b:16 * b + 16]
        gaps = {byte[i + 1][0] - byte[i][0] for i in range(15)}
        assert gaps == {half}, (div, b, gaps)
        assert [l for _, l in byte] == [1, 0] * 8


def test_data_read_back(spi):
    drv = spi
    bus(drv)
    eeprom_write(drv, 0, 0x60, b"\x11\x22\x33")
    got = eeprom_read(drv, 0, 0x60, 3)
    assert got == b"\xff\xff\x11\x22\x33"
    assert drv.rd(data_reg(drv), 3) == got[:3]
    assert drv.rd(data_reg(drv), 5) == got
    # another exchange replaces them
    assert xfer(drv, 0, b"\x05\x00")[0] == 0xFF
    assert drv.rd(data_reg(drv), 2) == drv.rd(data_reg(drv), 2)


def test_bit_order_mismatch_reverses_the_bits(spi):
    """LSB-first bus against an MSB-first device: each side sees the other's
    bytes reversed. Reversed WREN and RDSR work; the reply comes reversed."""
    drv = spi
    bus(drv, 2, 0, lsb=True)
    xfer(drv, 0, [rev(0x06)])                           # the device sees 06
    got = xfer(drv, 0, [rev(0x05), 0x00])               # the device sees 05
    assert got[1] == rev(0x02), got                     # WEL set, seen reversed
    bus(drv, 2, 0)
    assert xfer(drv, 0, b"\x05\x00")[1] == 0x02
    xfer(drv, 0, b"\x04")                               # WRDI
    assert xfer(drv, 0, b"\x05\x00")[1] == 0x00


def test_lsb_first_device(spi):
    drv = spi
    pin = DEV_PINS[drv.board][4]
    bind(drv, 1, pin)
    pullups(drv)                                        # the old line
    bus(drv, 3, 0, lsb=True)
    eeprom_write(drv, 1, 0x10, b"\xC1\x02\x80")
    assert eeprom_read(drv, 1, 0x10, 3) == b"\xff\xff\xc1\x02\x80"
    assert drv.ctl.spidev(pin).startswith("eeprom25 mode 0 lsb")


def test_clock_phase_mismatch_shifts_by_one_bit(spi):
    """Bus in mode 0 against the mode-1 device: the device still reads MOSI
    right, the master samples MISO one edge early (data shifted one bit)."""
    drv = spi
    bus(drv, 2, 1)
    eeprom_write(drv, 1, 0x40, b"\xA5\x3C\x81")
    right = eeprom_read(drv, 1, 0x40, 3)
    assert right == b"\xff\xff\xa5\x3c\x81"
    bus(drv, 2, 0)
    assert eeprom_read(drv, 1, 0x40, 3) == shifted(right)


def test_clock_polarity_mismatch_works_like_the_other_phase(spi):
    """docs: in mode 3 a mode-0 device samples on the same (rising) edges, so
    what the master writes arrives whole; what it sends back comes a bit
    early (it moves on the first, falling, edge)."""
    drv = spi
    bus(drv, 2, 3)
    eeprom_write(drv, 0, 0x48, b"\x5A\xC3")
    bus(drv, 2, 0)
    assert eeprom_read(drv, 0, 0x48, 2) == b"\xff\xff\x5a\xc3"
    bus(drv, 2, 3)
    assert eeprom_read(drv, 0, 0x48, 2) != b"\xff\xff\x5a\xc3"


@pytest.mark.parametrize("ch, mv", [(0, 0), (3, 1234), (5, 2500), (7, 4999)])
def test_mcp3008(spi, ch, mv):
    drv = spi
    bind(drv, 2, DEV_PINS[drv.board][5])
    pullups(drv)                                        # the old line
    bus(drv, 4, 0)
    drv.ctl.adc(ch, mv)
    try:
        got = xfer(drv, 2, bytes([0x01, 0x80 | ch << 4, 0x00]))
    finally:
        drv.ctl.adc(ch, 0)
    code = (got[1] & 0x03) << 8 | got[2]
    assert code == min(1023, 1024 * mv // 5000), (got, code)


def test_gpio_cannot_change_a_chip_select(spi):
    drv = spi
    pin = DEV_PINS[drv.board][0]
    i = drv.lay["gpio_ports"].index(pin[0])
    line = int(pin[1])
    for v in (0x00, 0xFF):
        drv.wr(drv.lay["gpio_mode"] + i, bytes([v, 1 << line]))
        drv.wr(drv.lay["gpio_val"] + i, bytes([0x00, 1 << line]))
        assert drv.pin(pin) == (1, "out")


def test_rebinding_gives_the_old_line_back(spi):
    drv = spi
    old = DEV_PINS[drv.board][3]
    new = DEV_PINS[drv.board][4]
    bind(drv, 3, new)
    assert drv.pin(old) == (0, "in")
    assert drv.pin(new) == (1, "out")
    assert drv.rd(cfg_reg(drv), 9)[7:9] == bytes(port_line(drv, new))


def rejections(board):
    busy = {"m32d": [("DIR1 PB0", bytes([0, 1, 0])), ("SCL PC0", bytes([0, 2, 0])),
                     ("RXD PD0", bytes([0, 3, 0])), ("PWM1 PD5", bytes([0, 3, 5]))],
            "m128s": []}[board]
    nports = 4 if board == "m32d" else 2
    return [
        ("2 bytes", bytes([0, 0]), BAD_LENGTH),
        ("4 bytes", bytes([0, 0, 1, 0]), BAD_LENGTH),
        ("channel 4", bytes([4, 0, 1]), BAD_VALUE),
        ("port", bytes([0, nports, 1]), BAD_VALUE),
        ("line 8", bytes([0, 0, 8]), BAD_VALUE),
        ("settings bit 6", bytes([0xFF, 0, 0x42]), BAD_VALUE),
        ("settings bit 7", bytes([0xFF, 0, 0x82]), BAD_VALUE),
    ] + [(name, data, PIN_BUSY) for name, data in busy]


@pytest.mark.parametrize("case", range(11))
def test_config_rejections(spi, case):
    drv = spi
    cases = rejections(drv.board)
    if case >= len(cases):
        pytest.skip("no such case on this board")
    name, data, status = cases[case]
    before = drv.rd(cfg_reg(drv), 9)
    pins = {p: drv.pin(p) for p in list(drv.lay["fixed_pins"]) + DEV_PINS[drv.board]}
    drv.wr_refused(cfg_reg(drv), data, status)
    assert drv.rd(cfg_reg(drv), 9) == before, name
    assert {p: drv.pin(p) for p in pins} == pins, name


def test_chip_select_of_another_channel_or_function(spi):
    drv = spi
    pins = DEV_PINS[drv.board]
    before = drv.rd(cfg_reg(drv), 9)
    drv.wr_refused(cfg_reg(drv), bytes([0]) + bytes(port_line(drv, pins[1])), PIN_BUSY)
    adc_idx = drv.lay["gpio_ports"].index(drv.lay["adc_port"])
    drv.wr(drv.lay["adc"], b"\x01\x40")                         # ADC 6 enabled
    drv.wr_refused(cfg_reg(drv), bytes([1, adc_idx, 6]), PIN_BUSY)
    assert drv.rd(cfg_reg(drv), 9) == before
    if drv.board == "m32d":
        drv.wr(drv.lay["servo"] + 1, bytes([11, 0x05, 0xDC]))  # servo 11 = PC4
        drv.wr_refused(cfg_reg(drv), bytes([1, 2, 4]), PIN_BUSY)
        assert drv.rd(cfg_reg(drv), 9) == before


@pytest.mark.parametrize("data, status", [
    (b"\x00", BAD_LENGTH),                  # no bytes to exchange
    (b"\x04\x05\x00", BAD_VALUE),           # channel 4
    (b"\xff\x05", BAD_VALUE),
])
def test_data_rejections(spi, data, status):
    drv = spi
    sck = drv.lay["spi_pins"]["SCK"]
    xfer(drv, 0, b"\x05\x00")
    before = drv.rd(data_reg(drv), 2)
    t0 = drv.now()
    drv.wr_refused(data_reg(drv), data, status)
    drv.wait(1000)
    assert drv.edges(sck, t0) == []
    assert drv.rd(data_reg(drv), 2) == before
    assert drv.ctl.spi() == [{"cs": DEV_PINS[drv.board][0], "mosi": b"\x05\x00",
                              "miso": before}]
