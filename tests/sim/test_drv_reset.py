"""Introspection records and the reset state of every driver, seen on the pins.

The simulator of this module is never written to (only reads and writes the
drivers refuse), so every test sees the board as it came out of reset
(docs/registers.md, "Conventions": servos send no pulses, motors are stopped,
all GPIO pins are inputs; docs/registers.md for each driver's reset state).
"""

import pytest

#: The records as written down by hand (UID, version, start, count), an oracle
#: apart from the generated map (docs/board-<board>.md, "Drivers").
RECORDS = {
    "m32d": ["0000 1.0 00 02", "0020 1.1 02 08", "0001 1.1 0A 02",
             "0040 1.1 0C 02", "0060 1.1 0E 04", "0031 2.0 12 02",
              "0002 1.0 14 02"],
    "m128s": ["0000 1.0 00 02", "0021 1.1 02 04", "0001 1.1 06 02",
              "0040 1.1 08 02", "0030 2.0 0A 02", "0002 1.0 0C 02"],
}


@pytest.fixture
def drv(drv_sim):
    """The board as reset left it: no driver state to put back afterwards
    (the tests only read and make refused writes)."""
    assert drv_sim.sim.running, drv_sim.sim.stderr
    drv_sim.gw.reset_input_buffer()
    mark = drv_sim.mark()
    yield drv_sim
    drv_sim.restore()
    assert drv_sim.events(mark, ["reset"]) == []


def record_bytes(text):
    uid, ver, start, count = text.split()
    major, minor = ver.split(".")
    return bytes.fromhex(uid) + bytes([int(major), int(minor),
                                       int(start, 16), int(count, 16)])


#: DDR of each GPIO port after reset (docs/registers.md, docs/boards.md):
#: GPIO lines are inputs; of the other functions' lines these are outputs:
#: motor DIR lines and PWM lines (driven low), SPI SS (output, high), SCK and
#: MOSI (the SPI master drives them). MISO is an input (SPI master).
#: The UART and TWI lines are left out of the comparison (the peripheral
#: drives them whatever DDR says; the docs fix no DDR bit for them).
RESET_DDR = {
    # port: (expected DDR, bits compared)
    "m32d": {"A": (0x00, 0xFF),
             "B": (0xB3, 0xFF),      # SCK MOSI SS DIR2 DIR1 out; S12 S13 MISO in
             "C": (0x00, 0xFC),      # SCL SDA (C0 C1) not compared
             "D": (0x30, 0xFC)},     # PWM1 PWM2 out; RXD TXD not compared
    "m128s": {"A": (0x00, 0xFF), "F": (0x00, 0xFF)},
}


def test_introspection_lists_exactly_the_boards_drivers(drv):
    want = [record_bytes(r) for r in RECORDS[drv.board]]
    assert drv.ask(drv.req("S AA 00 00 S AB 01 P")) == b"SWAASR%02XP\r\n" % len(want)
    for n, rec in enumerate(want, 1):
        assert drv.ask(drv.req("S AA 00 %02X S AB 06 P" % n)) == (
            b"SWAASR" + rec.hex().upper().encode() + b"P\r\n"), n
    # all of them in one read, then driver 1 again
    allrec = b"".join(want) + want[0]
    assert drv.ask(drv.req("S AA 00 01 S AB %02X P" % len(allrec))) == (
        b"SWAASR" + allrec.hex().upper().encode() + b"P\r\n")
    drv.wr_refused(0x00, bytes([len(want) + 1]), 0x02)     # BAD_VALUE


def test_servo_outputs_are_silent(drv):
    lay = drv.lay
    drv.wait(3 * 147456)                    # a few frames after start-up
    for sig in lay["servo_pins"]:
        assert drv.edges(sig, 0) == [], sig
        assert drv.ctl.level(sig) == 0, sig
    if drv.board == "m128s":
        # the counters: clocks never ticked, reset held high
        for sig in ("E3", "E4", "E5", "B7"):
            assert drv.edges(sig, 0) == [], sig
            assert drv.pin(sig) == (0, "out"), sig
        assert drv.pin("E6") == (1, "out")
        for c in range(4):
            assert drv.ctl.level("cnt%dq0" % c) == 1, c      # held in Q0
    else:
        for sig in lay["servo_pins"][:14]:
            assert drv.pin(sig) == (0, "in"), sig


def test_servo_registers(drv):
    lay = drv.lay
    n = lay["servo_channels"]
    assert drv.rd(lay["servo"], n // 8) == bytes(n // 8)          # RS: nothing pulses
    assert drv.rd(lay["servo"] + 1, 32) == bytes(32)              # SP: widths 0


def test_motor_outputs_low(drv):
    if drv.board != "m32d":
        pytest.skip("motors: OR-AVR-M32-D only")
    for sig in ("D5", "D4", "B0", "B1"):           # PWM1 PWM2 DIR1 DIR2
        assert drv.pin(sig) == (0, "out"), sig
        assert drv.edges(sig, 0) == [], sig
    assert drv.rd(drv.lay["motor"], 4) == bytes(4)


def test_gpio_lines_are_inputs(drv):
    lay = drv.lay
    for i, port in enumerate(lay["gpio_ports"]):
        want, compared = RESET_DDR[drv.board][port]
        ddr = drv.rd(lay["gpio_mode"] + i, 1)[0]
        assert ddr & compared == want, (port, hex(ddr))
        for line in range(8):
            name = "%s%d" % (port, line)
            if name in lay["fixed_pins"] or (compared >> line) & 1 == 0:
                continue
            if (want >> line) & 1 == 0:
                assert drv.pin(name) == (0, "in"), name      # no pull-up either
        # the value register reads the pin levels
        levels = drv.read_levels(port)
        assert drv.rd(lay["gpio_val"] + i, 1)[0] == levels, port


def test_spi_pins_and_config(drv):
    pins = drv.lay["spi_pins"]
    assert drv.pin(pins["SS"]) == (1, "out")
    assert drv.pin(pins["SCK"]) == (0, "out spi")        # mode 0: idles low
    assert drv.pin(pins["MOSI"])[1] == "out spi"
    assert drv.pin(pins["MISO"])[1].startswith("in")
    assert drv.rd(drv.lay["spi"] + 1, 9) == b"\x02" + b"\xff" * 8


def test_spi_data_unreadable_before_any_exchange(drv):
    drv.unreadable(drv.lay["spi"])                  # status 05 NOT_READABLE


@pytest.mark.parametrize("channel", [0, 1, 2, 3])
def test_spi_unbound_channel(drv, channel):
    sck = drv.lay["spi_pins"]["SCK"]
    t0 = drv.now()
    drv.wr_refused(drv.lay["spi"], bytes([channel, 0x05, 0x00]), 0x07)
    assert drv.edges(sck, t0) == []                 # nothing was clocked
    assert drv.ctl.spi() == []


def test_adc_off(drv):
    lay = drv.lay
    drv.wait(73728)
    assert drv.rd(lay["adc"], 2) == b"\x00\x00"
    assert drv.rd(lay["adc"] + 1, 8) == bytes(8)
    for line in range(8):
        assert drv.pin("%s%d" % (lay["adc_port"], line)) == (0, "in")
