"""The Python world's own sensor drivers, unmodified, on a simulated robot:
an M32-D gateway whose bus holds an M128-S slave board at 10 (7-bit 0x08)
and the simulator's sensor parts (docs/simulator.md): an MPU-6050 at D0
(0x68), an HMC5883L at 3C (0x1E), an LIS3MDL at 38 (0x1C), BMP280s at EC
(0x76, Pimoroni's default) and EE (0x77, Adafruit's) and a 24LC32 at A8
(0x54).

Through orfa.busio.I2C: Adafruit's adafruit_mpu6050, adafruit_lis3mdl,
adafruit_bmp280 and adafruit_24lc32; through orfa.smbus.SMBus: Pimoroni's
bmp280 (BMP280(i2c_dev=bus)), and the HMC5883L read against its datasheet
(identification, data order X Z Y, scale) with read_i2c_block_data. The
drivers are imported as installed (tools/setup.sh).

What the parts sense is set with the control request `sense`
(SimControl.sense), then simulated time is let run past the part's next
sample (`wait`, in cycles) before the driver reads. Every value a driver
returns is checked twice: equal to the datasheet's conversion of the raw
value the part must hold (the set value rounded to nearest code of the
range in use), and within half an LSB of that range (converted to the
driver's units) of the value set. Each reading goes into a table: the
value set, the value the driver returned, one LSB; it is written to
build/sensor-readings.txt, printed at the end of the pytest run, and must
stand in docs/sensors.md ("Simulated parts") row for row.

What the drivers do when their sensor is missing: tests/sim/test_busio_smbus.py
(a bus without the parts), and one more here (an MPU-6050 at the address
this robot leaves free)."""

import math
import struct
from pathlib import Path

import pytest

from conftest import (SENSOR_READINGS, ControlBench, raw, require_builds, require_slave,
                      running)
from orfa import boardmap
from orfa.busio import I2C
from orfa.sim import SimBoard
from orfa.smbus import SMBus
from test_sensors_baro import (P1, P2, P3, P4, P5, P6, P7, P8, P9, T1, T2, T3, press_double,
                               temp_double)

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs" / "sensors.md"
READINGS = ROOT / "build" / "sensor-readings.txt"
from conftest import F_CPU  # noqa: E402 (the clock from board.h, through the map)
G = 9.80665                              # m/s^2 per g, as the MPU-6050's driver has it

# 8-bit bus addresses (the parts, the slave) and their 7-bit forms (the drivers)
MPU, HMC, LIS, BMP_PIM, BMP_ADA, EE32, SLAVE8 = 0xD0, 0x3C, 0x38, 0xEC, 0xEE, 0xA8, 0x10
GATEWAY = 0x55                           # the gateway's own map (AA)
PARTS = [("mpu6050", MPU), ("hmc5883l", HMC), ("lis3mdl", LIS), ("bmp280", BMP_PIM),
         ("bmp280", BMP_ADA), ("24lc32", EE32)]


def ms(t: float) -> int:
    """Simulated cycles in T milliseconds."""
    return int(F_CPU * t / 1000) + 1


def need(module: str, package: str):
    return pytest.importorskip(module, reason="%s is not installed (tools/setup.sh installs it)"
                               % package)


# --- the readings table -----------------------------------------------------------------

def fmt(values) -> str:
    if isinstance(values, str):
        return values
    if isinstance(values, (tuple, list)):
        return ", ".join(fmt(v) for v in values)
    return "%.8g" % values


def table_row(driver: str, reading: str, set_, got, lsb) -> str:
    return "| %s | %s | %s | %s | %s |" % (driver, reading, fmt(set_), fmt(got), fmt(lsb))


def docs_rows() -> set:
    text = DOCS.read_text()
    return {line for line in text.splitlines() if line.startswith("| ")}


@pytest.fixture(scope="module")
def note(request):
    """note(DRIVER, READING, SET, GOT, LSB): a row of the table; the same row
    must be in docs/sensors.md. Every row of the module's run goes to
    build/sensor-readings.txt at its end (and the conftest prints it)."""
    rows = request.config.stash.setdefault(SENSOR_READINGS, [])
    documented = docs_rows()

    def add(driver, reading, set_, got, lsb):
        row = table_row(driver, reading, set_, got, lsb)
        rows.append(row)
        assert row in documented, ("docs/sensors.md's table of readings lacks\n%s\n(its rows "
                                   "are in %s after this run)" % (row, READINGS))

    yield add
    READINGS.parent.mkdir(parents=True, exist_ok=True)
    READINGS.write_text(TABLE_HEAD + "".join(r + "\n" for r in rows))


TABLE_HEAD = ("| driver | reading | set | the driver returned | one LSB |\n"
              "|---|---|---|---|---|\n")


def within(got, exact, set_, lsb):
    """GOT is the datasheet's value EXACT of the code the part must hold, and
    within half an LSB of the value SET (ties land on the half)."""
    got, exact, set_ = (list(x) if isinstance(x, (tuple, list)) else [x]
                        for x in (got, exact, set_))
    assert got == pytest.approx(exact, rel=1e-12, abs=1e-12)
    for g, s in zip(got, set_):
        assert abs(g - s) <= lsb * (0.5 + 1e-9), (got, set_, lsb)


# --- the robot ----------------------------------------------------------------------------

@pytest.fixture(scope="module")
def robot():
    require_builds(["m32d"])
    elf = require_slave("m128s", SLAVE8)
    sim = SimBoard("m32d", trace=False, control=True, slaves=[("m128s", SLAVE8, elf)],
                   parts=PARTS)
    with running(sim, ControlBench) as b:
        yield b


@pytest.fixture(scope="module")
def i2c(robot):
    """The bus as the drivers get it: not locked (their I2CDevice locks)."""
    bus = I2C(robot.gw)
    yield bus
    bus.deinit()


@pytest.fixture(scope="module")
def mpu(i2c):
    return need("adafruit_mpu6050", "adafruit-circuitpython-mpu6050").MPU6050(i2c)


@pytest.fixture(scope="module")
def lis(i2c):
    return need("adafruit_lis3mdl", "adafruit-circuitpython-lis3mdl").LIS3MDL(i2c)


@pytest.fixture(autouse=True)
def alive(robot):
    yield
    assert robot.sim.running, "the simulator died: %s" % robot.sim.stderr


def read_reg(i2c: I2C, addr7: int, reg: int, n: int) -> bytes:
    """N bytes from register REG (one request: register byte, repeated START, read)."""
    buf = bytearray(n)
    while not i2c.try_lock():
        pass
    try:
        i2c.writeto_then_readfrom(addr7, bytes([reg]), buf)
    finally:
        i2c.unlock()
    return bytes(buf)


# --- the bus --------------------------------------------------------------------------------

def test_every_sensor_and_the_slave_answer_on_one_bus(robot, i2c):
    expected = sorted([SLAVE8 >> 1, GATEWAY] + [addr >> 1 for _, addr in PARTS])
    while not i2c.try_lock():
        pass
    try:
        assert i2c.scan() == expected
    finally:
        i2c.unlock()


def test_the_slave_answers_its_introspection_between_sensor_reads(robot, i2c, mpu, note):
    """The slave board and the sensors share the bus in one run: the
    driver reads the MPU-6050, the slave board its driver count and a
    record (adafruit_register's UnaryStruct: register byte, repeated START,
    the same buffer), the MPU-6050 again."""
    I2CDevice = need("adafruit_bus_device.i2c_device", "adafruit-circuitpython-busdevice").I2CDevice
    UnaryStruct = need("adafruit_register.i2c_struct", "adafruit-circuitpython-register").UnaryStruct

    class Introspection:
        count = UnaryStruct(0x00, "<B")

        def __init__(self, bus, address):
            self.i2c_device = I2CDevice(bus, address)

    drivers = boardmap.load("m128s").drivers
    robot.ctl.sense(MPU, "temp", 30.0)
    robot.ctl.wait(ms(1))
    first = mpu.temperature
    intro = Introspection(i2c, SLAVE8 >> 1)
    intro.count = 0                                 # index 0: the count
    assert intro.count == len(drivers)
    intro.count = 1                                 # record 1, read on its own
    record = bytearray(6)
    while not i2c.try_lock():
        pass
    try:
        i2c.readfrom_into(SLAVE8 >> 1, record)
    finally:
        i2c.unlock()
    d = drivers[0]
    assert record == bytes([d.uid >> 8, d.uid & 0xFF, d.major, d.minor, d.start, d.count])
    assert mpu.temperature == first == raw(30.0 - 36.53, 340) / 340 + 36.53


def test_a_missing_mpu6050_is_the_drivers_own_error(i2c):
    """AD0 high (0x69, D2): nobody there on this robot."""
    mpu6050 = need("adafruit_mpu6050", "adafruit-circuitpython-mpu6050")
    with pytest.raises(ValueError, match="^No I2C device at address: 0x69$"):
        mpu6050.MPU6050(i2c, address=0x69)


# --- MPU-6050: adafruit_mpu6050 ------------------------------------------------------------

@pytest.mark.parametrize("range_name, lsb_per_g, accel", [
    ("RANGE_2_G", 16384, (1.5, -9.80665, 19.0)),
    ("RANGE_8_G", 4096, (30.25, -50.0, 9.80665)),
])
def test_mpu6050_acceleration(robot, mpu, note, range_name, lsb_per_g, accel):
    mpu6050 = need("adafruit_mpu6050", "adafruit-circuitpython-mpu6050")
    mpu.accelerometer_range = getattr(mpu6050.Range, range_name)
    robot.ctl.sense(MPU, "accel", *accel)
    robot.ctl.wait(ms(1))                           # a sample at 8 kHz: one after the other
    got = mpu.acceleration
    exact = [raw(a / G, lsb_per_g) / lsb_per_g * G for a in accel]
    within(got, exact, accel, G / lsb_per_g)
    note("adafruit_mpu6050", "acceleration (m/s^2), %s" % range_name, accel, got, G / lsb_per_g)


@pytest.mark.parametrize("range_name, lsb_per_dps, gyro", [
    ("RANGE_500_DPS", 65.5, (10.0, 123.4, -5.0)),      # the driver's default
    ("RANGE_250_DPS", 131, (-5.0, 0.5, 249.0)),
    ("RANGE_2000_DPS", 16.4, (-1500.0, 250.5, 1990.0)),
])
def test_mpu6050_gyro(robot, mpu, note, range_name, lsb_per_dps, gyro):
    """The gyroscope in rad/s, as the driver gives it: radians(code / LSB
    per degree/s). -5 degrees/s at +-500 is -327.5 codes, halfway between
    two: the part rounds to nearest with ties upward, so the register holds
    -327 (read here as the driver does, GYRO_ZOUT at 47), and the driver's
    arithmetic is exact on it: radians(-327 / 65.5) = -0.0871332 rad/s,
    half an LSB (0.000133 rad/s) from -0.0872665. Half an LSB is what the
    range resolves; neither the part, the driver nor the sample is off. At
    +-250 (131 per degree/s) -5 degrees/s is a code of its own: exact."""
    mpu6050 = need("adafruit_mpu6050", "adafruit-circuitpython-mpu6050")
    mpu.gyro_range = getattr(mpu6050.GyroRange, range_name)
    robot.ctl.sense(MPU, "gyro", *gyro)
    robot.ctl.wait(ms(1))
    got = mpu.gyro
    codes = [raw(v, lsb_per_dps) for v in gyro]
    assert list(struct.unpack(">3h", read_reg(mpu.i2c_device.i2c, 0x68, 0x43, 6))) == codes
    assert list(got) == [math.radians(c / lsb_per_dps) for c in codes]
    within(got, [math.radians(c / lsb_per_dps) for c in codes], [math.radians(v) for v in gyro],
           math.radians(1 / lsb_per_dps))
    note("adafruit_mpu6050", "gyro (rad/s), %s; sensed %s degrees/s" % (range_name, fmt(gyro)),
         [math.radians(v) for v in gyro], got, math.radians(1 / lsb_per_dps))


@pytest.mark.parametrize("celsius", [21.7, -12.25])
def test_mpu6050_temperature(robot, mpu, note, celsius):
    robot.ctl.sense(MPU, "temp", celsius)
    robot.ctl.wait(ms(1))
    got = mpu.temperature
    within(got, raw(celsius - 36.53, 340) / 340 + 36.53, celsius, 1 / 340)
    note("adafruit_mpu6050", "temperature (degrees C)", celsius, got, 1 / 340)


# --- LIS3MDL: adafruit_lis3mdl --------------------------------------------------------------

@pytest.mark.parametrize("range_name, lsb_per_gauss, field", [
    ("RANGE_4_GAUSS", 6842, (-35.2, 12.5, 48.9)),
    ("RANGE_12_GAUSS", 2281, (-900.0, 310.7, 1150.0)),
])
def test_lis3mdl_magnetic(robot, lis, note, range_name, lsb_per_gauss, field):
    """In microtesla (1 gauss = 100); the driver sets 155 Hz, a sample
    each 6.5 ms: two periods let run after the range and the field are set."""
    lis3mdl = need("adafruit_lis3mdl", "adafruit-circuitpython-lis3mdl")
    lis.range = getattr(lis3mdl.Range, range_name)
    robot.ctl.sense(LIS, "field", *field)
    robot.ctl.wait(ms(13))
    got = lis.magnetic
    within(got, [raw(f / 100, lsb_per_gauss) / lsb_per_gauss * 100 for f in field], field,
           100 / lsb_per_gauss)
    note("adafruit_lis3mdl", "magnetic (microtesla), %s" % range_name, field, got,
         100 / lsb_per_gauss)


# --- HMC5883L: the datasheet through SMBus ------------------------------------------------------

HMC7 = HMC >> 1
#: Gain by GN (CRB bits 7:5), LSB per gauss; a data register's range.
HMC_GAIN = [1370, 1090, 820, 660, 440, 390, 330, 230]


def hmc_measure(robot, bus) -> list:
    """A single measurement (mode register 02 = 01), 6 ms of simulated time
    for it, then the data registers 03..08 in one read: X, Z, Y, high byte
    first, as the datasheet orders them; [X, Y, Z]."""
    bus.write_byte_data(HMC7, 0x02, 0x01)
    robot.ctl.wait(ms(7))
    x, z, y = struct.unpack(">3h", bytes(bus.read_i2c_block_data(HMC7, 0x03, 6)))
    return [x, y, z]


def test_hmc5883l_identification(robot):
    with SMBus(robot.gw) as bus:
        assert bytes(bus.read_i2c_block_data(HMC7, 0x0A, 3)) == b"H43"


@pytest.mark.parametrize("gn, field", [
    (1, (23.4, -12.1, -41.7)),                      # the reset gain: 1090 LSB/gauss
    (5, (-450.0, 333.3, 120.5)),                    # 390 LSB/gauss, +-5.6 gauss
])
def test_hmc5883l_field_by_the_datasheet(robot, note, gn, field):
    """The gain goes to CRB; the datasheet: the first measurement after a
    gain change still uses the previous gain, so one is made and dropped."""
    gain = HMC_GAIN[gn]
    robot.ctl.sense(HMC, "field", *field)
    with SMBus(robot.gw) as bus:
        bus.write_byte_data(HMC7, 0x01, gn << 5)
        hmc_measure(robot, bus)
        codes = hmc_measure(robot, bus)
    assert codes == [raw(f / 100, gain) for f in field]
    got = [c / gain * 100 for c in codes]
    within(got, got, field, 100 / gain)
    note("SMBus + the HMC5883L datasheet", "field (microtesla), GN=%d" % gn, field, got,
         100 / gain)


def test_hmc5883l_overflow(robot):
    """Beyond a data register's -2048..2047 it reads -4096: 800 microtesla
    is 10960 codes at GN=0."""
    robot.ctl.sense(HMC, "field", 800, -30, 10)
    with SMBus(robot.gw) as bus:
        bus.write_byte_data(HMC7, 0x01, 0 << 5)
        hmc_measure(robot, bus)
        assert hmc_measure(robot, bus) == [-4096, raw(-0.3, 1370), raw(0.1, 1370)]


# --- BMP280: adafruit_bmp280 (busio) and Pimoroni's bmp280 (smbus) --------------------------------

def bmp_calibration(read) -> list:
    """dig_T1 .. dig_P9 (0x88..0x9F, little-endian; T1 and P1 unsigned)."""
    return list(struct.unpack("<HhhHhhhhhhhh", read(0x88, 24)))


def bmp_codes(read):
    """(adc_P, adc_T): 20 bits each at F7..F9 and FA..FC, high byte first."""
    d = read(0xF7, 6)
    return ((d[0] << 12 | d[1] << 4 | d[2] >> 4), (d[3] << 12 | d[4] << 4 | d[5] >> 4))


def bmp_t_fine(adc_t: float) -> float:
    """The datasheet's t_fine (section 8.1, the double version) before the
    truncation to an integer; degrees C = t_fine / 5120."""
    return temp_double(adc_t)[0] * 5120


def bmp_check(read, celsius, pa, t_step, p_step, int_t_fine):
    """The part holds the codes nearest to CELSIUS and PA at the resolution
    in use (codes T_STEP, P_STEP apart: 16 + oversampling bits with the
    filter off, 20 with it): within half the step to a neighbour, as the
    datasheet's formulas (t_fine an integer there) give them back. The
    values the driver must return from those codes, with its own t_fine
    (INT_T_FINE: truncated as the datasheet's int32, or not), and one LSB
    of each, in degrees C and Pa."""
    # the words the drivers read are the ones the formulas here have
    assert bmp_calibration(read) == [T1, T2, T3, P1, P2, P3, P4, P5, P6, P7, P8, P9]
    adc_p, adc_t = bmp_codes(read)
    assert adc_t % t_step == 0 and adc_p % p_step == 0, (adc_t, adc_p)
    temps = [bmp_t_fine(adc_t + k * t_step) / 5120 for k in (-1, 0, 1)]
    t_lsb = max(abs(temps[2] - temps[1]), abs(temps[1] - temps[0]))
    assert abs(temps[1] - celsius) <= t_lsb / 2
    t_fine = int(bmp_t_fine(adc_t))
    press = [press_double(adc_p + k * p_step, t_fine) for k in (-1, 0, 1)]
    p_lsb = max(abs(press[2] - press[1]), abs(press[1] - press[0]))
    assert abs(press[1] - pa) <= p_lsb / 2
    driver_t_fine = t_fine if int_t_fine else bmp_t_fine(adc_t)
    return driver_t_fine / 5120, press_double(adc_p, driver_t_fine), t_lsb, p_lsb


BMP_SENSED = [(21.5, 98765.4), (-5.25, 101325.0)]


@pytest.fixture(scope="module")
def bmp_adafruit(i2c):
    adafruit_bmp280 = need("adafruit_bmp280", "adafruit-circuitpython-bmp280")
    return adafruit_bmp280.Adafruit_BMP280_I2C(i2c)          # 0x77: EE


@pytest.mark.parametrize("celsius, pa", BMP_SENSED)
def test_adafruit_bmp280(robot, i2c, bmp_adafruit, note, celsius, pa):
    """The driver's defaults: forced mode (a measurement per reading, its
    end polled in the status register), temperature x2 (17 bits), pressure
    x16 (20 bits), no filter. Its own arithmetic: t_fine truncated to an
    integer (as the datasheet's int32), the temperature t_fine / 5120 (the
    datasheet's double version divides before truncating): up to 1/5120
    degrees C more."""
    bmp = bmp_adafruit
    robot.ctl.sense(BMP_ADA, "temp", celsius)
    robot.ctl.sense(BMP_ADA, "pressure", pa)
    t, p = bmp.temperature, bmp.pressure
    bmp.sea_level_pressure = 1013.25
    altitude = bmp.altitude
    want_t, want_p, t_lsb, p_lsb = bmp_check(lambda r, n: read_reg(i2c, BMP_ADA >> 1, r, n),
                                             celsius, pa, 8, 1, int_t_fine=True)
    assert t == pytest.approx(want_t, rel=1e-12) and abs(t - celsius) <= t_lsb / 2 + 1 / 5120
    assert p == pytest.approx(want_p / 100, rel=1e-12) and abs(p * 100 - pa) <= p_lsb
    # altitude: 44330 (1 - (p / sea level)^0.1903), the slope times a pressure LSB
    exact = 44330 * (1 - (pa / 101325) ** 0.1903)
    slope = 44330 * 0.1903 * (pa / 101325) ** (0.1903 - 1) / 101325        # m per Pa
    assert altitude == pytest.approx(44330 * (1 - (p / 1013.25) ** 0.1903), rel=1e-12)
    assert abs(altitude - exact) <= slope * p_lsb
    note("adafruit_bmp280", "temperature (degrees C)", celsius, t, t_lsb)
    note("adafruit_bmp280", "pressure (hPa)", pa / 100, p, p_lsb / 100)
    note("adafruit_bmp280", "altitude (m), sea_level_pressure 1013.25", exact, altitude,
         slope * p_lsb)


@pytest.fixture(scope="module")
def bmp_pimoroni(robot):
    BMP280 = need("bmp280", "bmp280").BMP280
    bus = SMBus(robot.gw)
    bmp = BMP280(i2c_dev=bus)                                # 0x76: EC
    bmp.setup()
    yield bmp
    bus.close()


@pytest.mark.parametrize("celsius, pa", BMP_SENSED)
def test_pimoroni_bmp280_through_smbus(robot, bmp_pimoroni, note, celsius, pa):
    """Pimoroni's driver takes the SMBus as i2c_dev; its setup: normal mode,
    x16 both, filter 2 (so 20 bits), 500 ms standby: a measurement each
    565.5 ms of simulated time, two let run. Its own arithmetic: t_fine
    not truncated, for the temperature and the pressure alike."""
    robot.ctl.sense(BMP_PIM, "temp", celsius)
    robot.ctl.sense(BMP_PIM, "pressure", pa)
    robot.ctl.wait(ms(2 * 565.5))
    t, hpa = bmp_pimoroni.get_temperature(), bmp_pimoroni.get_pressure()
    with SMBus(robot.gw) as bus:
        want_t, want_p, t_lsb, p_lsb = bmp_check(
            lambda r, n: bytes(bus.read_i2c_block_data(BMP_PIM >> 1, r, n)),
            celsius, pa, 1, 1, int_t_fine=False)
    assert t == pytest.approx(want_t, rel=1e-12) and abs(t - celsius) <= t_lsb
    assert hpa == pytest.approx(want_p / 100, rel=1e-12) and abs(hpa * 100 - pa) <= p_lsb
    note("Pimoroni bmp280 (SMBus)", "temperature (degrees C)", celsius, t, t_lsb)
    note("Pimoroni bmp280 (SMBus)", "pressure (hPa)", pa / 100, hpa, p_lsb / 100)


# --- 24LC32: adafruit_24lc32 ------------------------------------------------------------------------

def test_adafruit_24lc32_bytes_and_slices(i2c, note):
    """The driver writes byte by byte (a two-byte word address, the byte,
    5 ms of its own sleep for the write cycle) and reads a slice in one
    transfer: the last byte, a slice across a 32-byte page boundary, and
    the longest slice one request reads (60 bytes after the two address
    bytes; one more is orfa.busio's ValueError, never two transfers)."""
    EEPROM_I2C = need("adafruit_24lc32", "adafruit-circuitpython-24lc32").EEPROM_I2C
    eeprom = EEPROM_I2C(i2c, address=EE32 >> 1)
    assert len(eeprom) == 4096
    eeprom[0x0FFF] = 0xA5
    assert eeprom[0x0FFF] == b"\xa5"
    eeprom[0x003E:0x0042] = [0x10, 0x20, 0x30, 0x40]
    assert eeprom[0x003E:0x0042] == b"\x10\x20\x30\x40"
    assert eeprom[0x0000:0x003C] == b"\xff" * 0x3C            # erased, as shipped
    with pytest.raises(ValueError, match="reads at most 60 after 2 written"):
        eeprom[0x0000:0x003D]
    note("adafruit_24lc32", "eeprom[0x0FFF]", "0xA5", "0x%02X" % eeprom[0x0FFF][0], "exact")
    note("adafruit_24lc32", "eeprom[0x003E:0x0042]", "10 20 30 40",
         eeprom[0x003E:0x0042].hex(" "), "exact")
