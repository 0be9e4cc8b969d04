"""The simulated MPU-6050, HMC5883L and LIS3MDL (`--part`, sim/parts/,
docs/simulator.md) as a PC sees them through the gateway's serial port, with
what they sense set over the control socket (`sense @ADDR QUANTITY V...`)
and every wait in simulated cycles (`wait`, or requests put on the serial
line at chosen cycles with `rx`), never on the wall clock.

Every expected register value is computed here from the datasheets'
formulas, not read back from the model:

* MPU-6050 (InvenSense register map rev 4.2): WHO_AM_I (75) 0x68 at either
  address, PWR_MGMT_1 (6B) resets to 0x40 (asleep), everything else to 0;
  accelerometer 16384/8192/4096/2048 LSB/g by AFS_SEL, gyroscope 131/65.5/
  32.8/16.4 LSB per degree/s by FS_SEL, temperature raw/340 + 36.53; high
  byte first; samples at 8 kHz or 1 kHz / (1 + SMPLRT_DIV).
* HMC5883L (Honeywell datasheet rev E): identification 'H' '4' '3' at 10..12,
  data X, Z, Y high byte first at 03..08, 1370 .. 230 LSB/gauss by GN,
  -4096 on overflow, a single measurement 6 ms after the command, the
  pointer from 08 back to 03 and from 12 to 00.
* LIS3MDL (ST DocID024204): WHO_AM_I (0F) 0x3D, 6842/3421/2281/1711 LSB/gauss
  for +-4/8/12/16 gauss, low byte first, temperature 8 LSB per degree C
  around 25; multi-byte reads auto-increment with or without SUB bit 7 (the
  silicon, which Adafruit's driver relies on) and wrap from OUT_Z_H to
  OUT_X_L.

One gateway board suffices: the parts are the simulator's, not the board's.
"""

import re
import struct
import subprocess

import pytest

from orfa.sim import sim_path
from orfa.simctl import SimControlError

from conftest import F_CPU, Bench, bench_running, for_each_test, raw

MPU, MPU2, HMC, LIS = 0xD0, 0xD2, 0x3C, 0x38
G = 9.80665                             # m/s^2 per g
LEAD = F_CPU // 2                       # how far ahead requests are put on the line


def cycles_us(us: int) -> int:
    return (F_CPU * us + 999999) // 1000000


def s16_be(data: bytes):
    return list(struct.unpack(">%dh" % (len(data) // 2), data))


def s16_le(data: bytes):
    return list(struct.unpack("<%dh" % (len(data) // 2), data))


class SensorBench(Bench):
    def __init__(self, sim):
        super().__init__(sim)
        self.ctl = sim.control

    def read(self, addr: int, reg: int, n: int) -> bytes:
        """N bytes from register REG: write the pointer, repeated START, read."""
        reply = self.ask("S %02X %02X S %02X %02X P" % (addr, reg, addr | 1, n))
        assert reply[:5] == b"SWASR" and reply[-3:] == b"P\r\n", reply
        return bytes.fromhex(reply[5:-3].decode())

    def read_on(self, addr: int, n: int) -> bytes:
        """N bytes from where the pointer is (no register byte)."""
        reply = self.ask("S %02X %02X P" % (addr | 1, n))
        assert reply[:2] == b"SR" and reply[-3:] == b"P\r\n", reply
        return bytes.fromhex(reply[2:-3].decode())

    def write(self, addr: int, reg: int, *data: int) -> None:
        request = "S %02X %02X%s P" % (addr, reg, "".join(" %02X" % d for d in data))
        assert self.ask(request) == b"SW" + b"A" * (1 + len(data)) + b"P\r\n", request

    def rx(self, cycle: int, line: str) -> int:
        return self.ctl.rx(cycle, line.encode("ascii") + b"\n")

    def twi(self, since: int, kind: str):
        return [(e.cycle, e.fields) for e in self.events(since, ["twi " + kind])]

    def lag(self, line: str, kind: str, nth: int) -> int:
        """Cycles from a request's first byte on the serial line to its
        NTH bus event of KIND ("write", "read"): sent once to measure."""
        mark = self.mark()
        t = self.ctl.time() + LEAD
        self.rx(t, line)
        self.read_lines(1)
        return self.twi(mark, kind)[nth][0] - t


@pytest.fixture(scope="module")
def bench():
    yield from bench_running("m32d", SensorBench, trace=True, control=True,
                             parts=[("mpu6050", MPU), ("mpu6050", MPU2), ("hmc5883l", HMC),
                                    ("lis3mdl", LIS)])


@pytest.fixture
def b(bench):
    yield from for_each_test(bench, settle=True)


@pytest.fixture
def mpu(b):
    """The MPU-6050 at D0 as after power-up (DEVICE_RESET), sensing rest."""
    b.write(MPU, 0x6B, 0x80)
    b.ctl.sense(MPU, "accel", 0, 0, 0)
    b.ctl.sense(MPU, "gyro", 0, 0, 0)
    b.ctl.sense(MPU, "temp", 25)
    yield b
    b.write(MPU, 0x6B, 0x80)


@pytest.fixture
def lis(b):
    """The LIS3MDL after SOFT_RST: power-down, +-4 gauss."""
    b.write(LIS, 0x21, 0x04)
    b.ctl.sense(LIS, "field", 0, 0, 0)
    b.ctl.sense(LIS, "temp", 25)
    yield b
    b.write(LIS, 0x21, 0x04)


# --- MPU-6050 -------------------------------------------------------------------

def test_mpu_identity_and_reset_values(mpu):
    assert mpu.read(MPU, 0x75, 1) == b"\x68"
    assert mpu.read(MPU2, 0x75, 1) == b"\x68"      # AD0 high: same WHO_AM_I
    assert mpu.read(MPU, 0x6B, 2) == b"\x40\x00"   # PWR_MGMT_1 asleep, PWR_MGMT_2
    assert mpu.read(MPU, 0x19, 4) == bytes(4)      # SMPLRT_DIV .. ACCEL_CONFIG
    assert mpu.read(MPU, 0x37, 2) == bytes(2)      # INT_PIN_CFG, INT_ENABLE
    assert mpu.read(MPU, 0x6A, 1) == b"\x00"       # USER_CTRL


def test_mpu_asleep_measures_nothing(mpu):
    """Powered up asleep: what it senses does not reach the registers
    until SLEEP is cleared."""
    mpu.ctl.sense(MPU, "accel", 1, 2, 3)
    mpu.ctl.wait(cycles_us(2000))
    assert mpu.read(MPU, 0x3B, 14) == bytes(14)
    mpu.write(MPU, 0x6B, 0x00)
    mpu.ctl.wait(cycles_us(2000))
    assert s16_be(mpu.read(MPU, 0x3B, 6)) == [raw(a / G, 16384) for a in (1, 2, 3)]


@pytest.mark.parametrize("afs, fs", [(0, 0), (3, 2)])
def test_mpu_readings_at_two_ranges(mpu, afs, fs):
    """One 14-byte burst from ACCEL_XOUT_H: accel X Y Z, temp, gyro X Y Z,
    each as its range's formula gives it."""
    accel, gyro, temp = (0.5, -9.80665, 3.3), (12.5, -100.0, 0.3), 31.7
    mpu.write(MPU, 0x1B, fs << 3, afs << 3)         # GYRO_CONFIG, ACCEL_CONFIG
    mpu.write(MPU, 0x6B, 0x01)                      # awake, PLL on gyro X
    mpu.ctl.sense(MPU, "accel", *accel)
    mpu.ctl.sense(MPU, "gyro", *gyro)
    mpu.ctl.sense(MPU, "temp", temp)
    mpu.ctl.wait(cycles_us(1000))
    words = s16_be(mpu.read(MPU, 0x3B, 14))
    a_lsb = 16384 >> afs
    g_lsb = (131, 65.5, 32.8, 16.4)[fs]
    assert words[:3] == [raw(a / G, a_lsb) for a in accel]
    assert words[3] == raw(temp - 36.53, 340)
    assert words[4:] == [raw(g, g_lsb) for g in gyro]
    # the values back within one LSB, as a driver computes them
    assert all(abs(w / a_lsb * G - a) <= G / a_lsb for w, a in zip(words[:3], accel))
    assert abs(words[3] / 340 + 36.53 - temp) <= 1 / 340


def test_mpu_saturates_at_full_scale(mpu):
    mpu.write(MPU, 0x1B, 0x00, 0x00)                # +-250 degrees/s, +-2 g
    mpu.write(MPU, 0x6B, 0x00)
    mpu.ctl.sense(MPU, "accel", 3 * G, -3 * G, 2 * G)
    mpu.ctl.sense(MPU, "gyro", 300, -251, 249)
    mpu.ctl.wait(cycles_us(1000))
    assert s16_be(mpu.read(MPU, 0x3B, 6)) == [32767, -32768, 32767]
    assert s16_be(mpu.read(MPU, 0x43, 6)) == [32767, -32768, raw(249, 131)]
    mpu.write(MPU, 0x1B, 0x18, 0x18)                # +-2000 degrees/s, +-16 g
    mpu.ctl.wait(cycles_us(1000))
    assert s16_be(mpu.read(MPU, 0x3B, 6)) == [raw(3, 2048), raw(-3, 2048), 4096]
    assert s16_be(mpu.read(MPU, 0x43, 6)) == [raw(300, 16.4), raw(-251, 16.4), raw(249, 16.4)]


def test_mpu_register_pointer(mpu):
    """Writes and reads move the address on; it stays across STOP and
    repeated START; read-only registers ignore writes."""
    mpu.write(MPU, 0x1B, 0x08, 0x10)                # two registers in one write
    assert mpu.read(MPU, 0x1B, 2) == b"\x08\x10"
    assert mpu.read_on(MPU, 1) == b"\x00"          # 1D: the pointer went on to it
    assert mpu.ask("S D0 75 P") == b"SWAP\r\n"
    assert mpu.read_on(MPU, 1) == b"\x68"          # across the STOP
    assert mpu.read(MPU, 0x74, 2) == b"\x00\x68"   # FIFO_R_W, then WHO_AM_I
    mpu.write(MPU, 0x75, 0x12)                      # read-only: acknowledged, kept
    assert mpu.read(MPU, 0x75, 1) == b"\x68"
    assert mpu.read(MPU, 0x0D, 4) == bytes([0x75, 0x77, 0x6B, 0x59])  # SELF_TEST trim


def test_mpu_device_reset(mpu):
    mpu.write(MPU, 0x19, 0x07, 0x03, 0x18, 0x18)   # 1 kHz / 8, +-2000, +-16 g
    mpu.write(MPU, 0x6B, 0x00)
    mpu.ctl.sense(MPU, "accel", 0, 0, G)
    mpu.ctl.wait(cycles_us(8000))
    assert s16_be(mpu.read(MPU, 0x3F, 2)) == [2048]
    mpu.write(MPU, 0x6B, 0x80)                      # DEVICE_RESET
    assert mpu.read(MPU, 0x6B, 1) == b"\x40"        # done at once, asleep again
    assert mpu.read(MPU, 0x19, 4) == bytes(4)
    assert mpu.read(MPU, 0x3B, 14) == bytes(14)


def test_mpu_temperature_off_and_axis_standby(mpu):
    mpu.write(MPU, 0x6B, 0x00)
    mpu.ctl.sense(MPU, "temp", 40)
    mpu.ctl.sense(MPU, "accel", G, G, G)
    mpu.ctl.wait(cycles_us(1000))
    mpu.write(MPU, 0x6B, 0x08)                      # TEMP_DIS
    mpu.write(MPU, 0x6C, 0x20)                      # STBY_XA
    mpu.ctl.sense(MPU, "temp", 20)
    mpu.ctl.sense(MPU, "accel", -G, -G, -G)
    mpu.ctl.wait(cycles_us(1000))
    assert s16_be(mpu.read(MPU, 0x3B, 8)) == [16384, -16384, -16384, raw(40 - 36.53, 340)]


def test_mpu_sample_rate_and_data_ready(mpu):
    """DLPF on (1 kHz) and SMPLRT_DIV 99: a sample each 100 ms from the
    write that wakes it; the registers show what was sensed at the last
    sample; DATA_RDY_INT (with DATA_RDY_EN) sets with each, a read of
    INT_STATUS clears it."""
    ctl = mpu.ctl
    period = F_CPU // 10
    mpu.write(MPU, 0x19, 99, 0x01)                  # SMPLRT_DIV 99, DLPF_CFG 1
    mpu.write(MPU, 0x38, 0x01)                      # DATA_RDY_EN
    wake, poll = "S D0 6B 00 P", "S D0 3A S D1 03 P"  # INT_STATUS, .., ACCEL_XOUT_H
    wake_lag = mpu.lag("S D0 6B 40 P", "write", 1)  # the same length, stays asleep
    poll_lag = mpu.lag(poll, "read", 0)
    ctl.sense(MPU, "accel", G, 0, 0)
    t = ctl.time() + LEAD
    mpu.rx(t, wake)
    woke = t + wake_lag
    for at in (woke + period - 30000, woke + period + 30000, woke + period + 60000):
        mpu.rx(at - poll_lag, poll)
    assert mpu.read_lines(4) == (b"SWAAP\r\n" + b"SWASR000000P\r\n" + b"SWASR014000P\r\n"
                                 + b"SWASR004000P\r\n")
    ctl.sense(MPU, "accel", 2 * G, 0, 0)
    ctl.wait(period)
    assert mpu.read(MPU, 0x3B, 2) == b"\x7f\xff"    # 2 g at +-2 g: saturated


def test_mpu_int_rd_clear(mpu):
    """DATA_RDY_INT stays until INT_STATUS is read; with INT_RD_CLEAR any
    read clears it. Asleep again after a sample, so no new one comes."""
    def one_sample():
        mpu.write(MPU, 0x6B, 0x00)
        mpu.ctl.wait(cycles_us(2000))
        mpu.write(MPU, 0x6B, 0x40)

    mpu.write(MPU, 0x38, 0x01)                      # DATA_RDY_EN
    one_sample()
    assert mpu.read(MPU, 0x3B, 1) == b"\x00"
    assert mpu.read(MPU, 0x3A, 1) == b"\x01"
    assert mpu.read(MPU, 0x3A, 1) == b"\x00"        # read: cleared
    mpu.write(MPU, 0x37, 0x10)                      # INT_RD_CLEAR
    one_sample()
    assert mpu.read(MPU, 0x3B, 1) == b"\x00"        # any read clears it
    assert mpu.read(MPU, 0x3A, 1) == b"\x00"


# --- HMC5883L ---------------------------------------------------------------------

HMC_GAIN = (1370, 1090, 820, 660, 440, 390, 330, 230)
HMC_MS = cycles_us(6000)                         # single measurement: 6 ms


def hmc_xzy(field_ut, gain):
    """The data registers' X, Z, Y for a field X, Y, Z in microtesla."""
    out = []
    for ut in (field_ut[0], field_ut[2], field_ut[1]):
        v = raw(ut / 100, gain, -5000, 5000)
        out.append(v if -2048 <= v <= 2047 else -4096)
    return out


@pytest.fixture
def hmc(b):
    """The HMC5883L idle at its reset configuration, gain 1 loaded (two
    measurements), no data unread, nothing locked."""
    b.write(HMC, 0x00, 0x10, 0x20)
    hmc_single(b)
    hmc_single(b)
    b.ctl.sense(HMC, "field", 0, 0, 0)
    yield b
    b.write(HMC, 0x00, 0x10, 0x20, 0x03)


def hmc_single(b):
    """A single measurement, waited for; the six data registers, read."""
    b.write(HMC, 0x02, 0x01)
    b.ctl.wait(HMC_MS)
    return s16_be(b.read(HMC, 0x03, 6))


def test_hmc_identity_and_registers(b):
    assert b.read(HMC, 10, 3) == b"H43"
    assert b.read_on(HMC, 2) == b"\x10\x20"       # 12 -> 00: CRA, CRB
    # its power-up single measurement is long done: the mode reads idle
    assert b.read(HMC, 0x00, 3) == b"\x10\x20\x03"
    assert b.read(HMC, 0x09, 1) == b"\x03"          # RDY; reading the mode set LOCK
    b.read(HMC, 0x03, 6)
    assert b.read(HMC, 0x09, 1) == b"\x00"          # all six read: neither
    assert b.read(HMC, 13, 2) == b"\x00\x10"       # invalid: 0; from 13 on to 00


def test_hmc_data_order_and_gain(hmc):
    b = hmc
    field = (20.0, -15.0, 40.0)                     # microtesla, X Y Z
    b.ctl.sense(HMC, "field", *field)
    b.write(HMC, 0x01, 0x20)                        # gain 1: 1090 LSB/gauss
    hmc_single(b)
    assert hmc_single(b) == hmc_xzy(field, 1090) == [218, 436, -163]
    b.write(HMC, 0x01, 0xA0)                        # gain 5: 390 LSB/gauss ...
    assert hmc_single(b) == hmc_xzy(field, 1090)    # ... from the second measurement
    assert hmc_single(b) == hmc_xzy(field, 390)
    b.write(HMC, 0x01, 0x20)
    hmc_single(b)


def test_hmc_overflow_reads_minus_4096(hmc):
    b = hmc
    b.write(HMC, 0x01, 0x00)                        # gain 0: +-0.88 gauss
    hmc_single(b)
    b.ctl.sense(HMC, "field", 150, 0, -80)          # 1.5 gauss: beyond 2047 counts
    assert hmc_single(b) == [-4096, raw(-0.8, 1370), 0]
    b.write(HMC, 0x01, 0xE0)                        # gain 7: 230 LSB/gauss
    hmc_single(b)
    assert hmc_single(b) == hmc_xzy((150, 0, -80), 230) == [345, -184, 0]
    b.write(HMC, 0x01, 0x20)
    hmc_single(b)


def test_hmc_pointer_rules(hmc):
    """Reads go from 08 back to 03; writes move the pointer on too."""
    b = hmc
    b.ctl.sense(HMC, "field", 10, 20, 30)
    b.write(HMC, 0x00, 0x18, 0x20, 0x01)            # CRA 75 Hz, CRB, mode: one write
    b.ctl.wait(HMC_MS)
    assert b.read(HMC, 0x00, 2) == b"\x18\x20"
    x, z, y = hmc_xzy((10, 20, 30), 1090)
    assert s16_be(b.read(HMC, 0x03, 8)) == [x, z, y, x]
    assert s16_be(b.read_on(HMC, 4)) == [z, y]     # 05 on, across the STOP
    b.write(HMC, 0x09, 0x55)                        # read-only: acknowledged, ignored
    b.write(HMC, 0x00, 0x90)                        # CRA bit 7 is not writable
    assert b.read(HMC, 0x00, 1) == b"\x10"


def test_hmc_single_measurement_takes_6_ms(hmc):
    """RDY (cleared by reading all six data registers) sets 6 ms after the
    command and the mode register then reads idle (0x03)."""
    b = hmc
    ctl = b.ctl
    b.read(HMC, 0x03, 6)
    assert b.read(HMC, 0x09, 1) == b"\x00"          # read: RDY clear, unlocked
    cmd, poll = "S 3C 02 01 P", "S 3C 09 S 3D 01 P"
    cmd_lag = b.lag("S 3C 02 03 P", "write", 1)     # idle: measures nothing
    poll_lag = b.lag(poll, "read", 0)
    t = ctl.time() + LEAD
    b.rx(t, cmd)
    done = t + cmd_lag + HMC_MS
    for at in (done - 15000, done + 15000):
        b.rx(at - poll_lag, poll)
    assert b.read_lines(3) == b"SWAAP\r\n" + b"SWASR00P\r\n" + b"SWASR01P\r\n"
    assert b.read(HMC, 0x02, 1) == b"\x03"
    b.read(HMC, 0x03, 6)


def test_hmc_lock(hmc):
    """Some of the six data registers read: LOCK, and new measurements wait
    until the rest are read (continuous at 0.75 Hz: one each 4/3 s)."""
    b = hmc
    b.ctl.sense(HMC, "field", 10, 0, 0)
    b.write(HMC, 0x00, 0x00)                        # 0.75 Hz
    b.write(HMC, 0x02, 0x00)
    b.ctl.wait(HMC_MS)
    assert s16_be(b.read(HMC, 0x03, 2)) == [109]    # X alone
    assert b.read(HMC, 0x09, 1) == b"\x03"          # LOCK, RDY
    b.ctl.sense(HMC, "field", 20, 0, 0)
    b.ctl.wait(F_CPU * 4 // 3 + 1)                  # the next measurement: held back
    assert s16_be(b.read(HMC, 0x03, 2)) == [109]
    assert b.read(HMC, 0x09, 1) == b"\x03"
    assert s16_be(b.read(HMC, 0x05, 4)) == [0, 0]   # the rest of the old set ...
    assert b.read(HMC, 0x09, 1) == b"\x01"          # ... unlocks: the new one is placed
    assert s16_be(b.read(HMC, 0x03, 6)) == [218, 0, 0]


def test_hmc_self_test_bias(hmc):
    """Positive and negative bias: the self-test field, +-1.16 gauss on X
    and Y and +-1.08 on Z, at gain 5 (the datasheet's self-test gain)."""
    b = hmc
    b.write(HMC, 0x01, 0xA0)
    hmc_single(b)
    b.write(HMC, 0x00, 0x71)                        # 8 averages, 15 Hz, positive bias
    assert hmc_single(b) == [raw(1.16, 390), raw(1.08, 390), raw(1.16, 390)]
    b.write(HMC, 0x00, 0x72)
    assert hmc_single(b) == [raw(-1.16, 390), raw(-1.08, 390), raw(-1.16, 390)]
    b.write(HMC, 0x00, 0x10, 0x20)
    hmc_single(b)


def test_hmc_continuous(hmc):
    """Continuous at 75 Hz: a new set each 1/75 s after the first, 6 ms on."""
    b = hmc
    ctl = b.ctl
    b.write(HMC, 0x00, 0x18)                        # 75 Hz
    b.write(HMC, 0x02, 0x00)
    ctl.sense(HMC, "field", 0, 0, 10)
    ctl.wait(HMC_MS + F_CPU // 75)
    assert s16_be(b.read(HMC, 0x03, 6)) == hmc_xzy((0, 0, 10), 1090)
    ctl.sense(HMC, "field", 0, 0, -10)
    ctl.wait(F_CPU // 75 + 1)
    assert s16_be(b.read(HMC, 0x03, 6)) == hmc_xzy((0, 0, -10), 1090)
    b.write(HMC, 0x00, 0x10, 0x20, 0x03)            # back to idle


# --- LIS3MDL ----------------------------------------------------------------------

LIS_LSB = (6842, 3421, 2281, 1711)
LIS_80HZ = F_CPU // 80 + 1


def lis_continuous(b, fs, ctrl1=0x1C):
    """Continuous at 80 Hz (or CTRL1), full scale FS; one period waited."""
    b.write(LIS, 0x20, ctrl1, fs << 5, 0x00)        # CTRL_REG1..3
    b.ctl.wait(LIS_80HZ)


def test_lis_identity_and_reset_values(lis):
    assert lis.read(LIS, 0x0F, 1) == b"\x3D"
    assert lis.read(LIS, 0x20, 5) == b"\x10\x00\x03\x00\x00"
    assert lis.read(LIS, 0x30, 4) == b"\xE8\x00\x00\x00"
    assert lis.read(LIS, 0x27, 1) == b"\x00"
    # power-down (the reset mode) measures nothing
    lis.ctl.sense(LIS, "field", 10, 20, 30)
    lis.ctl.wait(F_CPU // 10)
    assert lis.read(LIS, 0x28, 6) == bytes(6)


@pytest.mark.parametrize("fs", [0, 2])
def test_lis_field_at_two_ranges(lis, fs):
    """+-4 and +-12 gauss; read as Adafruit's driver does (6 bytes from 0x28,
    SUB bit 7 clear) and as the datasheet says (0xA8)."""
    field = (25.0, -42.5, 180.0)                    # microtesla
    lis.ctl.sense(LIS, "field", *field)
    lis_continuous(lis, fs)
    want = [raw(f / 100, LIS_LSB[fs]) for f in field]
    assert s16_le(lis.read(LIS, 0x28, 6)) == want
    assert s16_le(lis.read(LIS, 0xA8, 6)) == want
    assert all(abs(w / LIS_LSB[fs] * 100 - f) <= 100 / LIS_LSB[fs] for w, f in zip(want, field))


def test_lis_saturates_at_full_scale(lis):
    lis.ctl.sense(LIS, "field", 500, -500, 399)
    lis_continuous(lis, 0)
    assert s16_le(lis.read(LIS, 0x28, 6)) == [4 * 6842, -4 * 6842, raw(3.99, 6842)]
    lis_continuous(lis, 3)
    assert s16_le(lis.read(LIS, 0x28, 6)) == [raw(5, 1711), raw(-5, 1711), raw(3.99, 1711)]


def test_lis_pointer_rules(lis):
    """A read goes on from OUT_Z_H back to OUT_X_L (the silicon); TEMP_OUT
    is read on its own and goes on to INT_CFG; writes move on too."""
    lis.ctl.sense(LIS, "field", 10, 20, 30)
    lis.ctl.sense(LIS, "temp", 30.5)
    lis_continuous(lis, 0, ctrl1=0x9C)              # TEMP_EN, 80 Hz
    x, y, z = (raw(v / 100, 6842) for v in (10, 20, 30))
    assert s16_le(lis.read(LIS, 0x28, 8)) == [x, y, z, x]
    assert lis.read(LIS, 0x2E, 3) == bytes([raw(5.5, 8), 0, 0xE8])
    assert lis.read(LIS, 0x20, 1) == b"\x9C"
    lis.write(LIS, 0x0F, 0x00)                      # read-only
    assert lis.read(LIS, 0x0F, 1) == b"\x3D"
    lis.write(LIS, 0x21, 0xFF)                      # undefined bits, REBOOT, SOFT_RST...
    assert lis.read(LIS, 0x20, 5) == b"\x10\x00\x03\x00\x00"   # ... SOFT_RST won


def test_lis_status_and_endianness(lis):
    """Single conversions (exactly one sample each): DA per axis, cleared
    by reading its high byte; a sample over unread data sets OR."""
    ctl = lis.ctl
    ctl.sense(LIS, "field", -10, 0, 100)
    lis.write(LIS, 0x20, 0x1C, 0x00, 0x01)          # 80 Hz, +-4 gauss, single
    ctl.wait(LIS_80HZ)
    assert lis.read(LIS, 0x27, 1) == b"\x0F"        # ZYXDA, ZDA, YDA, XDA
    lis.read(LIS, 0x28, 2)                          # X taken
    assert lis.read(LIS, 0x27, 1) == b"\x0E"
    lis.write(LIS, 0x22, 0x01)
    ctl.wait(LIS_80HZ)                              # Y and Z overwritten unread
    assert lis.read(LIS, 0x27, 1) == b"\xEF"
    lis.write(LIS, 0x23, 0x02)                      # BLE: high byte first
    assert s16_be(lis.read(LIS, 0x28, 6)) == [raw(-0.1, 6842), 0, raw(1, 6842)]
    assert lis.read(LIS, 0x27, 1) == b"\x00"


def test_lis_single_conversion(lis):
    lis.ctl.sense(LIS, "field", 0, 50, 0)
    lis.write(LIS, 0x20, 0x1C)                      # 80 Hz
    lis.write(LIS, 0x22, 0x01)                      # single
    lis.ctl.wait(LIS_80HZ)
    assert lis.read(LIS, 0x22, 1) == b"\x03"        # back to power-down
    assert s16_le(lis.read(LIS, 0x28, 6)) == [0, raw(0.5, 6842), 0]


def test_lis_block_data_update(lis):
    """BDU: a sample waits until both bytes of the axis being read are read."""
    ctl = lis.ctl
    lis.write(LIS, 0x24, 0x40)
    ctl.sense(LIS, "field", 10, 0, 0)
    lis_continuous(lis, 0)
    low = lis.read(LIS, 0x28, 1)                    # X low byte alone
    ctl.sense(LIS, "field", -10, 0, 0)
    ctl.wait(LIS_80HZ)
    assert s16_le(low + lis.read(LIS, 0x29, 1)) == [raw(0.1, 6842)]
    assert s16_le(lis.read(LIS, 0x28, 2)) == [raw(-0.1, 6842)]


# --- sense errors, the kinds listed ------------------------------------------------

@pytest.mark.parametrize("bad, says", [
    ("sense @D0 field 1 2 3", "an MPU-6050 does not sense field; it senses accel, gyro, temp"),
    ("sense @D0 accel 0 0 157", "accel 157 is outside an MPU-6050's range"),
    ("sense @D0 accel 1 2", "accel takes 3 values, not 2"),
    ("sense @D0 gyro 0 -2001 0", "gyro -2001 is outside"),
    ("sense @D0 temp 86", "temp 86 is outside"),
    ("sense @3C temp 20", "an HMC5883L does not sense temp; it senses field"),
    ("sense @3C field 801 0 0", "field 801 is outside an HMC5883L's range -800..800 microtesla"),
    ("sense @38 field 0 0 -1601", "field -1601 is outside an LIS3MDL's range"),
    ("sense @38 pressure 101325", "an LIS3MDL does not sense pressure"),
    ("sense @38 temp -41", "temp -41 is outside"),
])
def test_sense_errors(b, bad, says):
    with pytest.raises(SimControlError, match="^ERR sense: " + re.escape(says)):
        b.ctl.request(bad)


def test_help_lists_the_kinds():
    r = subprocess.run([str(sim_path()), "--help"], capture_output=True, text=True, timeout=30)
    lines = {line.split()[0]: line for line in r.stderr.splitlines() if line.startswith("  ")}
    assert "at 0xD0, 0xD2; senses accel, gyro, temp" in lines["mpu6050"]
    assert "at 0x3C; senses field" in lines["hmc5883l"]
    assert "at 0x38, 0x3C; senses field, temp" in lines["lis3mdl"]


@pytest.mark.parametrize("part, says", [
    ("mpu6050@0xD4", "bad --part 'mpu6050@0xD4' (ADDR: 0xD0, 0xD2)"),
    ("lis3mdl@0x3A", "bad --part 'lis3mdl@0x3A' (ADDR: 0x38, 0x3C)"),
    ("hmc5883l@0x3C:fast", "bad part hmc5883l at 0x3C: no options"),
])
def test_bad_part_options(part, says):
    r = subprocess.run([str(sim_path()), "--board", "m32d", "--link", "/nonexistent/link",
                        "--part", part, "x.elf"], capture_output=True, text=True, timeout=30)
    assert r.returncode == 2
    assert r.stderr.strip().splitlines() == ["orfa-sim: " + says]
