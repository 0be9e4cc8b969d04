"""The simulated BMP280 barometer and 24LC32 EEPROM (`--part bmp280@0xEC`,
`--part 24lc32@0xA8`, docs/simulator.md) as a PC sees them through the
gateway's serial port, with what the barometer senses set over the control
socket (`sense @EC temp T`, `sense @EC pressure P`) and every wait in
simulated cycles.

Numbers from the datasheets: Bosch BST-BMP280-DS001 (chip id 0x58, reset
word 0xB6, the register map, the compensation formulas of section 8 and the
example calibration of section 3.12: adc_T 519888 is 25.08 degrees C, adc_P
415148 then 100653.27 Pa; the typical measurement time of section 9: 1 ms +
2 ms per temperature sample + 2 ms per pressure sample + 0.5 ms) and
Microchip's 24LC32A (two word-address bytes, 32-byte pages, tWC 5 ms,
address not acknowledged during the write cycle, sequential reads roll over
from 0xFFF to 0x000).
"""

import os
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from orfa.sim import SimBoard, part_kinds
from orfa.simctl import SimControlError

from conftest import F_CPU, ControlBench, bench_running, for_each_test, require_builds

BARO = 0xEC
EE = 0xA8
EE_WP = 0xAC
TWC = F_CPU * 5 // 1000                 # the 24LC32A's write cycle
STARTUP = F_CPU * 2 // 1000             # the BMP280's NVM copy after a reset
ENV = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2] / "host"))
#: How far ahead of "now" bytes are scheduled with `rx` (see test_srf08.py).
LEAD = F_CPU // 2

# --- the datasheet's compensation, as a driver computes it ---------------------

T1, T2, T3 = 27504, 26435, -1000
P1, P2, P3, P4, P5, P6, P7, P8, P9 = 36477, -10685, 3024, 2855, 140, -7, 15500, -14600, 6000


def s32(x):
    x &= 0xFFFFFFFF
    return x - (1 << 32) if x & 0x80000000 else x


def u32(x):
    return x & 0xFFFFFFFF


def temp_int32(adc_t):
    """bmp280_compensate_T_int32: (hundredths of a degree C, t_fine)."""
    var1 = s32((s32((adc_t >> 3) - (T1 << 1)) * T2) >> 11)
    var2 = s32((s32((s32((adc_t >> 4) - T1) * s32((adc_t >> 4) - T1)) >> 12) * T3) >> 14)
    t_fine = s32(var1 + var2)
    return s32((t_fine * 5 + 128) >> 8), t_fine


def press_int32(adc_p, t_fine):
    """bmp280_compensate_P_int32: Pa."""
    var1 = (t_fine >> 1) - 64000
    var2 = s32(s32(s32((var1 >> 2) * (var1 >> 2)) >> 11) * P6)
    var2 = s32(var2 + s32(s32(var1 * P5) << 1))
    var2 = s32((var2 >> 2) + (P4 << 16))
    var1 = s32((s32(s32(P3 * (s32((var1 >> 2) * (var1 >> 2)) >> 13)) >> 3)
                + (s32(P2 * var1) >> 1)) >> 18)
    var1 = s32(s32((32768 + var1) * P1) >> 15)
    if var1 == 0:
        return 0
    p = u32(u32(u32(1048576 - adc_p) - (var2 >> 12)) * 3125)
    if p < 0x80000000:
        p = u32(p << 1) // u32(var1)
    else:
        p = u32((p // u32(var1)) * 2)
    var1 = s32((P9 * s32(u32((p >> 3) * (p >> 3)) >> 13)) >> 12)
    var2 = s32((s32(p >> 2) * P8) >> 13)
    return u32(s32(p) + ((var1 + var2 + P7) >> 4))


def temp_double(adc_t):
    """bmp280_compensate_T_double: (degrees C, t_fine)."""
    var1 = (adc_t / 16384.0 - T1 / 1024.0) * T2
    var2 = (adc_t / 131072.0 - T1 / 8192.0) * (adc_t / 131072.0 - T1 / 8192.0) * T3
    return (var1 + var2) / 5120.0, int(var1 + var2)


def press_double(adc_p, t_fine):
    """bmp280_compensate_P_double: Pa."""
    var1 = t_fine / 2.0 - 64000.0
    var2 = var1 * var1 * P6 / 32768.0
    var2 = var2 + var1 * P5 * 2.0
    var2 = var2 / 4.0 + P4 * 65536.0
    var1 = (P3 * var1 * var1 / 524288.0 + P2 * var1) / 524288.0
    var1 = (1.0 + var1 / 32768.0) * P1
    if var1 == 0.0:
        return 0
    p = 1048576.0 - adc_p
    p = (p - var2 / 4096.0) * 6250.0 / var1
    var1 = P9 * p * p / 2147483648.0
    var2 = p * P8 / 32768.0
    return p + (var1 + var2 + P7) / 16.0


def test_the_formulas_here_are_the_datasheets():
    """Section 3.12's example, through the formulas as written above (the
    32-bit pressure formula truncates: 3 Pa above the others there)."""
    assert temp_int32(519888) == (2508, 128422)
    assert temp_double(519888) == (pytest.approx(25.0825, abs=1e-4), 128422)
    assert press_double(415148, 128422) == pytest.approx(100653.27, abs=0.02)
    assert press_int32(415148, 128422) == 100656


def meas_cycles(osrs_t, osrs_p):
    """The typical measurement time in cycles (datasheet section 9)."""
    def n(osrs):
        return 0 if osrs == 0 else min(16, 1 << (osrs - 1))
    us = 1000 + 2000 * n(osrs_t) + (2000 * n(osrs_p) + 500 if osrs_p else 0)
    return F_CPU * us // 1000000


# --- the bench -------------------------------------------------------------------------

class PartBench(ControlBench):
    def edge(self, start: str, started, probe: str, probed, duration: int):
        """Probes just before and just after the end of something `duration`
        cycles long that the request line `start` begins at the cycle
        started(mark) finds in the trace. The request line `probe` is put on
        the serial line so that its bus event (probed(mark): (cycle,
        outcome)) lands 60 cycles before the end, then in another round 60
        after; the firmware's main loop adds some tens of cycles of jitter to
        a line's way to the bus, so a probe that lands on the wrong side is
        tried again 150, then 300 cycles off. [(cycle - end, outcome, the
        two replies)] of the last round on each side."""
        ctl = self.ctl
        mark = self.mark()
        t = ctl.time() + LEAD
        self.rx(t, start)
        self.read_lines(1)
        start_lag = started(mark) - t
        ctl.wait(duration)
        mark = self.mark()
        t = ctl.time() + LEAD
        self.rx(t, probe)
        self.read_lines(1)
        probe_lag = probed(mark)[0] - t
        rounds = []
        for side in (-1, 1):
            for margin in (60, 150, 300):
                ctl.wait(duration)
                mark = self.mark()
                t = ctl.time() + LEAD
                self.rx(t, start)
                self.rx(t + start_lag + duration + side * margin - probe_lag, probe)
                replies = self.read_lines(2)
                cycle, outcome = probed(mark)
                offset = cycle - started(mark) - duration
                if (offset < 0) == (side < 0):
                    break
            rounds.append((offset, outcome, replies))
        return rounds

    def rd(self, dev: int, reg: bytes, count: int) -> bytes:
        """Write the register/word address, repeated START, read `count`."""
        reply = self.ask("S %02X %s S %02X %02X P" % (dev, reg.hex(" "), dev | 1, count))
        head = b"SW" + b"A" * len(reg) + b"SR"
        assert reply.startswith(head) and reply.endswith(b"P\r\n"), reply
        return bytes.fromhex(reply[len(head):-3].decode())

    def wr(self, dev: int, data: bytes) -> None:
        assert self.ask("S %02X %s P" % (dev, data.hex(" "))) == (
            b"SW" + b"A" * len(data) + b"P\r\n")

    def baro(self, reg: int, count: int) -> bytes:
        return self.rd(BARO, bytes([reg]), count)

    def baro_set(self, *pairs: int) -> None:
        """Register/value pairs in one write, as the BMP280 takes them."""
        self.wr(BARO, bytes(pairs))


@pytest.fixture(scope="module")
def parts_bench():
    yield from bench_running("m32d", PartBench, trace=True, control=True,
                             parts=[("bmp280", BARO), ("24lc32", EE), ("24lc32", EE_WP, "wp")])


def reset_baro(b):
    b.baro_set(0xE0, 0xB6)
    b.ctl.wait(max(STARTUP, TWC))


@pytest.fixture
def parts(parts_bench):
    """The board with the BMP280 just reset and idle, the EEPROMs ready."""
    yield from for_each_test(parts_bench, prepare=reset_baro, settle=True)


# --- BMP280 ---------------------------------------------------------------------------------

def test_chip_id_and_reset_values(parts):
    assert parts.baro(0xD0, 1) == b"\x58"
    assert parts.baro(0xF3, 10) == bytes.fromhex("00 00 00 00 80 00 00 80 00 00")


def test_calibration_words(parts):
    """dig_T1 .. dig_P9 at 0x88..0x9F, LSB first: the datasheet's example."""
    words = struct.unpack("<HhhHhhhhhhhh", parts.baro(0x88, 24))
    assert words == (T1, T2, T3, P1, P2, P3, P4, P5, P6, P7, P8, P9)


def test_reset_register(parts):
    """0xB6 to 0xE0 resets every register; another value does nothing; the
    register reads 0; im_update is set while the NVM is copied (2 ms)."""
    parts.baro_set(0xF5, 0xA8, 0xF4, 0x24)
    assert parts.baro(0xF4, 2) == b"\x24\xA8"
    parts.baro_set(0xE0, 0x55)
    assert parts.baro(0xE0, 1) == b"\x00"
    assert parts.baro(0xF4, 2) == b"\x24\xA8"
    # the reset, then the status in the same request (a repeated START):
    # read within the 2 ms, whatever the wall clock does between requests
    mark = parts.mark()
    assert parts.ask("S EC E0 B6 S EC F3 S ED 03 P") == b"SWAASWASR010000P\r\n"
    reset_at = parts.twi(mark, "write")[1][0]
    read_at = parts.twi(mark, "read")[0][0]
    assert read_at < reset_at + STARTUP
    parts.ctl.wait(STARTUP)
    assert parts.baro(0xF3, 1) == b"\x00"


def test_writes_are_register_value_pairs(parts):
    """No auto-increment on writes: F5 A0 F4 24 sets F5 and F4; the
    register address is kept across STOP for a read without one."""
    parts.baro_set(0xF5, 0xA0, 0xF4, 0x24)
    assert parts.ask("S ED 02 P") == b"SR24A0P\r\n"   # from F4: the last address written
    assert parts.ask("S ED 02 P") == b"SR0080P\r\n"   # on: F6 (not in the map), press_msb


def adc20(data: bytes) -> int:
    return (data[0] << 12) | (data[1] << 4) | (data[2] >> 4)


def forced(parts, osrs_t, osrs_p, filt=0):
    """One forced measurement; (adc_T, adc_P)."""
    parts.baro_set(0xF5, filt << 2, 0xF4, (osrs_t << 5) | (osrs_p << 2) | 1)
    parts.ctl.wait(meas_cycles(osrs_t, osrs_p))
    data = parts.baro(0xF7, 6)
    return adc20(data[3:]), adc20(data[:3])


@pytest.mark.parametrize("osrs_t, osrs_p, filt, bits_t, bits_p", [
    (1, 1, 0, 16, 16),         # ultra low power: x1 x1, 16 bits each
    (2, 5, 0, 17, 20),         # ultra high resolution: x2 x16
    (1, 3, 2, 20, 20),         # with the IIR filter: 20 bits whatever the oversampling
])
@pytest.mark.parametrize("temp, press", [(25.0, 101325.0), (-12.34, 85000.5), (84.9, 30500.0),
                                         (-39.5, 109900.0)])
def test_what_is_sensed_comes_back_through_the_formulas(parts, osrs_t, osrs_p, filt, bits_t,
                                                        bits_p, temp, press):
    parts.ctl.sense(BARO, "temp", temp)
    parts.ctl.sense(BARO, "pressure", press)
    adc_t, adc_p = forced(parts, osrs_t, osrs_p, filt)
    step_t, step_p = 1 << (20 - bits_t), 1 << (20 - bits_p)
    assert adc_t % step_t == 0 and adc_p % step_p == 0, (hex(adc_t), hex(adc_p))
    # the nearest raw value of that resolution: within half a step
    t, t_fine = temp_double(adc_t)
    half_t = (temp_double(adc_t + step_t)[0] - t) / 2
    assert abs(t - temp) <= half_t + 1e-9
    p = press_double(adc_p, t_fine)
    half_p = (p - press_double(adc_p + step_p, t_fine)) / 2
    assert abs(p - press) <= half_p + 1e-9
    # the integer versions: their own rounding on top (0.01 degrees; the
    # 32-bit pressure formula's truncation, under 5 Pa over the range)
    t100, t_fine_int = temp_int32(adc_t)
    assert abs(t100 / 100 - temp) <= half_t + 0.007
    assert abs(press_int32(adc_p, t_fine_int) - press) <= half_p + 5


def test_a_skipped_measurement_reads_0x80000(parts):
    parts.ctl.sense(BARO, "temp", 20)
    adc_t, adc_p = forced(parts, 1, 0)
    assert adc_p == 0x80000 and abs(temp_double(adc_t)[0] - 20) < 0.01
    adc_t, adc_p = forced(parts, 0, 1)
    assert adc_t == 0x80000 and adc_p != 0x80000


@pytest.mark.parametrize("osrs_t, osrs_p, t_meas", [
    (1, 1, F_CPU * 55 // 10000),        # x1 x1: 5.5 ms
    (2, 5, F_CPU * 375 // 10000),       # x2 x16: 37.5 ms
])
def test_forced_mode_timing_and_status(parts, osrs_t, osrs_p, t_meas):
    """measuring (status bit 3) from the ctrl_meas write for the typical
    measurement time exactly, then sleep (mode 00) and the results in the
    registers. Polls are put on the serial line at chosen cycles so that
    their reads land just before and just after the end, whatever the wall
    clock does."""
    assert meas_cycles(osrs_t, osrs_p) == t_meas
    ctrl = (osrs_t << 5) | (osrs_p << 2)
    parts.ctl.sense(BARO, "temp", 30)
    rounds = parts.edge("S EC F4 %02X P" % (ctrl | 1),
                        lambda mark: parts.twi(mark, "write")[1][0],   # the F4 value
                        "S EC F3 S ED 01 P", lambda mark: parts.twi(mark, "read")[-1],
                        t_meas)
    (before, status_before, replies_before), (after, status_after, replies_after) = rounds
    assert -400 < before < 0 <= after < 400, rounds
    assert (status_before, status_after) == (("08", "nack"), ("00", "nack"))
    assert replies_before == b"SWAAP\r\nSWASR08P\r\n"
    assert replies_after == b"SWAAP\r\nSWASR00P\r\n"
    assert parts.baro(0xF4, 1) == bytes([ctrl])           # back to sleep
    assert abs(temp_double(adc20(parts.baro(0xFA, 3)))[0] - 30) < 0.003


def test_normal_mode_follows_what_is_sensed(parts):
    """Mode 11 measures every measurement time + t_sb and stays in normal
    mode; config writes are ignored there (drivers sleep the part first)."""
    parts.ctl.sense(BARO, "pressure", 90000)
    parts.baro_set(0xF5, 0x00, 0xF4, 0x27)            # t_sb 0.5 ms, x1 x1, normal
    period = meas_cycles(1, 1) + F_CPU // 2000
    parts.ctl.wait(period + meas_cycles(1, 1))
    first = adc20(parts.baro(0xF7, 3))
    parts.ctl.sense(BARO, "pressure", 100000)
    parts.ctl.wait(2 * period)
    second = adc20(parts.baro(0xF7, 3))
    t_fine = temp_double(adc20(parts.baro(0xFA, 3)))[1]
    assert abs(press_double(first, t_fine) - 90000) < 2
    assert abs(press_double(second, t_fine) - 100000) < 2
    parts.baro_set(0xF5, 0xE0)
    assert parts.baro(0xF4, 2) == b"\x27\x00"
    parts.baro_set(0xF4, 0x24, 0xF5, 0xE0)             # asleep: taken
    assert parts.baro(0xF4, 2) == b"\x24\xE0"


@pytest.mark.parametrize("bad, says", [
    ("sense @EC accel 0 0 9.8", "a BMP280 senses temp T and pressure P, not accel"),
    ("sense @EC temp 85.1", "-40..85 degrees C"),
    ("sense @EC temp -40.5", "-40..85 degrees C"),
    ("sense @EC pressure 29999", "30000..110000 Pa"),
    ("sense @EC pressure 110001", "30000..110000 Pa"),
    ("sense @EC temp 20 21", "not temp with 2 values"),
    ("sense @EC range 100", "a BMP280 senses temp T and pressure P"),
    ("sense @A8 temp 20", "the 24lc32 at A8 senses nothing"),
])
def test_sense_errors(parts, bad, says):
    with pytest.raises(SimControlError, match="^ERR .*" + re.escape(says)):
        parts.ctl.request(bad)


def test_sense_errors_change_nothing(parts):
    parts.ctl.sense(BARO, "temp", 10)
    with pytest.raises(SimControlError, match="-40..85"):
        parts.ctl.sense(BARO, "temp", 100)
    adc_t, _ = forced(parts, 1, 1)
    assert abs(temp_double(adc_t)[0] - 10) < 0.003


# --- 24LC32 ---------------------------------------------------------------------------------

def ee_write(parts, addr: int, data: bytes, dev: int = EE) -> None:
    parts.wr(dev, addr.to_bytes(2, "big") + data)
    parts.ctl.wait(TWC)


def ee_read(parts, addr: int, count: int, dev: int = EE) -> bytes:
    return parts.rd(dev, addr.to_bytes(2, "big"), count)


def test_two_byte_word_addresses(parts):
    """12 bits: 0x123 and 0x023 are different bytes; the high byte's upper
    four bits are don't-care (F1 23 is 0x123)."""
    ee_write(parts, 0x123, b"\xAB\xCD")
    assert ee_read(parts, 0x123, 2) == b"\xAB\xCD"
    assert ee_read(parts, 0xF123, 2) == b"\xAB\xCD"
    assert ee_read(parts, 0x023, 2) == b"\xFF\xFF"


def test_a_page_write_wraps_inside_its_page(parts):
    """From 0x0FE (offset 30 of the page 0x0E0): 30, 31, then 0, 1 of the
    same page; 0x100 (the next page) untouched."""
    ee_write(parts, 0x0FE, b"\x11\x22\x33\x44")
    assert ee_read(parts, 0x0FE, 3) == b"\x11\x22\xFF"
    assert ee_read(parts, 0x0E0, 3) == b"\x33\x44\xFF"


def test_a_full_page_and_more(parts):
    """33 bytes into one 32-byte page: the 33rd overwrites the first."""
    data = bytes(range(0x40, 0x61))
    ee_write(parts, 0x200, data)
    assert ee_read(parts, 0x200, 32) == bytes([0x60]) + data[1:32]
    assert ee_read(parts, 0x220, 1) == b"\xFF"


def test_write_cycle_is_not_acknowledged_for_twc(parts):
    """From the write's STOP the chip does not acknowledge its address for
    tWC (5 ms, 36864 cycles); acknowledge polling: NACK just before, ACK
    just after. Its neighbour at AC answers all along. The requests are
    put on the serial line at chosen cycles (as in test_srf08.py)."""
    ctl = parts.ctl

    def stop(mark):
        return parts.twi(mark, "stop")[0][0]

    def probed(mark):
        return [(c, f[1]) for c, f in parts.twi(mark, "addr") if f[0] == "A8"][-1]

    rounds = parts.edge("S A8 03 00 5A P", stop, "S A8 P", probed, TWC)
    (before, ack_before, replies_before), (after, ack_after, replies_after) = rounds
    assert -400 < before < 0 <= after < 400, rounds
    assert (ack_before, ack_after) == ("nack", "ack")
    assert replies_before == b"SWAAAP\r\nERROR 06\r\n"
    assert replies_after == b"SWAAAP\r\nSWP\r\n"
    # early in the cycle: the neighbour answers, the chip does not
    ctl.wait(TWC)
    t = ctl.time() + LEAD
    end = parts.rx(t, "S A8 03 01 A5 P")
    end = parts.rx(end + 2000, "S AC P")
    parts.rx(end + 2000, "S A8 P")
    assert parts.read_lines(3) == b"SWAAAP\r\nSWP\r\nERROR 06\r\n"
    ctl.wait(TWC)
    assert ee_read(parts, 0x300, 2) == b"\x5A\xA5"


def test_a_read_or_an_address_alone_starts_no_write_cycle(parts):
    assert parts.ask("S A8 04 00 P") == b"SWAAP\r\n"
    assert parts.ask("S A8 P") == b"SWP\r\n"
    assert parts.ask("S A9 01 P") == b"SRFFP\r\n"
    assert parts.ask("S A8 P") == b"SWP\r\n"


def test_sequential_read_rolls_over_the_whole_array(parts):
    """Reads cross pages and roll over from 0xFFF to 0x000."""
    ee_write(parts, 0xFFE, b"\x5A\xA5")
    ee_write(parts, 0x000, b"\xC3")
    ee_write(parts, 0x41F, b"\x01")
    ee_write(parts, 0x420, b"\x02")
    assert ee_read(parts, 0xFFE, 3) == b"\x5A\xA5\xC3"
    assert ee_read(parts, 0x41F, 2) == b"\x01\x02"


def test_the_address_pointer_is_kept_across_stop(parts):
    """A current address read goes on from the last byte accessed + 1."""
    ee_write(parts, 0x510, b"\x10\x11\x12\x13")
    assert ee_read(parts, 0x510, 2) == b"\x10\x11"
    assert parts.ask("S A9 02 P") == b"SR1213P\r\n"
    assert parts.ask("S A8 05 11 P") == b"SWAAP\r\n"
    assert parts.ask("S A9 01 P") == b"SR11P\r\n"


def test_a_repeated_start_abandons_the_data(parts):
    """The write cycle needs a STOP (assumed: the datasheet names none other)."""
    assert parts.ask("S A8 06 00 77 S A9 01 P") == b"SWAAASRFFP\r\n"
    assert parts.ask("S A8 P") == b"SWP\r\n"
    assert ee_read(parts, 0x600, 1) == b"\xFF"


def test_write_protected(parts):
    """WP high: the data bytes are acknowledged, nothing is written and no
    write cycle follows (the next address is acknowledged at once)."""
    assert parts.ask("S AC 00 00 12 34 P") == b"SWAAAAP\r\n"
    assert parts.ask("S AC P") == b"SWP\r\n"
    assert ee_read(parts, 0x000, 2, dev=EE_WP) == b"\xFF\xFF"


# --- the command line -----------------------------------------------------------------------

def test_orfa_sim_part_scan():
    """`orfa --sim m32d --part bmp280@0xEC scan`: the barometer on the bus."""
    require_builds(["m32d"])
    result = subprocess.run([sys.executable, "-m", "orfa", "--sim", "m32d", "--part",
                             "bmp280@0xEC", "--part", "24lc32@0xA8", "scan"],
                            capture_output=True, text=True, timeout=60, env=ENV)
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[-1] == "8-bit: 0xA8 0xAA 0xEC (0xAA: the gateway itself)"


@pytest.mark.parametrize("part, says", [
    ("bmp280@0xA0", "orfa: orfa-sim: bad --part 'bmp280@0xA0' (ADDR: 0xEC, 0xEE)\n"),
    ("24lc32@0xB0", "orfa: orfa-sim: bad --part '24lc32@0xB0' (ADDR: 0xA0 .. 0xAE)\n"),
    ("bmp280@0xEC:fast", "orfa: orfa-sim: bad part bmp280 at 0xEC: no options\n"),
    ("24lc32@0xA8:ro", "orfa: orfa-sim: bad part 24lc32 at 0xA8: bad option (wp)\n"),
])
def test_what_only_the_part_knows_is_one_line(part, says):
    """A kind's own addresses and options are the simulator's to check: its
    one line, exit 2 (not the three lines of a simulator that died)."""
    require_builds(["m32d"])
    result = subprocess.run([sys.executable, "-m", "orfa", "--sim", "m32d", "--part", part,
                             "version"], capture_output=True, text=True, timeout=60, env=ENV)
    assert (result.returncode, result.stdout, result.stderr) == (2, "", says)


def test_an_unknown_part_names_the_kinds():
    """The kinds are the simulator's own (`orfa-sim --help` lists them)."""
    require_builds(["m32d"])
    kinds = part_kinds()
    assert {"eeprom24", "srf08", "bmp280", "24lc32"} <= set(kinds)
    result = subprocess.run([sys.executable, "-m", "orfa", "--sim", "m32d", "--part",
                             "bmp380@0xEC", "version"], capture_output=True, text=True,
                            timeout=60, env=ENV)
    assert (result.returncode, result.stdout, result.stderr) == (
        2, "", "orfa: error: argument --part: 'bmp380@0xEC': no part 'bmp380' (the"
               " simulator's: %s) (orfa --help)\n" % ", ".join(kinds))


# --- the drivers robot builders use -------------------------------------------------------

def test_adafruit_and_pimoroni_bmp280_drivers_read_what_was_set():
    """Unmodified drivers over orfa.busio and orfa.smbus: Adafruit's at its
    defaults (normal mode, x2 temperature, x16 pressure) and forced, then
    Pimoroni's (x2/x16 as well: 17 and 20 bits); within a step of their
    resolution (0.0025 degrees C; 0.2 Pa)."""
    adafruit_bmp280 = pytest.importorskip("adafruit_bmp280",
                                          reason="tools/setup.sh installs it")
    pimoroni = pytest.importorskip("bmp280", reason="tools/setup.sh installs it")
    from orfa.busio import I2C
    from orfa.smbus import SMBus
    require_builds(["m32d"])
    with SimBoard("m32d", trace=False, control=True, parts=[("bmp280", BARO)]) as sim, \
            sim.gateway() as gw:
        sim.control.sense(BARO, "temp", 21.37)
        sim.control.sense(BARO, "pressure", 98765.4)
        sensor = adafruit_bmp280.Adafruit_BMP280_I2C(I2C(gw), address=BARO >> 1)
        sim.control.wait(meas_cycles(2, 5) + F_CPU // 2000)   # its first measurement
        assert sensor.temperature == pytest.approx(21.37, abs=0.0025)
        assert sensor.pressure * 100 == pytest.approx(98765.4, abs=0.2)    # hPa
        sim.control.sense(BARO, "temp", -5.5)
        sim.control.sense(BARO, "pressure", 101000)
        sensor.mode = adafruit_bmp280.MODE_FORCE
        assert sensor.temperature == pytest.approx(-5.5, abs=0.0025)
        assert sensor.pressure * 100 == pytest.approx(101000, abs=0.2)
        bmp = pimoroni.BMP280(i2c_dev=SMBus(gw), i2c_addr=BARO >> 1)
        bmp.setup(mode="forced")
        assert bmp.get_temperature() == pytest.approx(-5.5, abs=0.0025)
        assert bmp.get_pressure() * 100 == pytest.approx(101000, abs=0.2)
