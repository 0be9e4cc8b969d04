"""The Python world's own sensor drivers, unmodified, on a simulated robot:
an M32-D gateway whose bus holds an M128-S slave board at 10 (7-bit 0x08)
and the simulator's sensor parts (docs/simulator.md): an MPU-6050 at D0
(0x68), an HMC5883L at 3C (0x1E), an LIS3MDL at 38 (0x1C) and, where the
simulator has them, BMP280s at EC (0x76, Pimoroni's default) and EE (0x77,
Adafruit's) and a 24LC32 at A8 (0x54).

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

from conftest import SENSOR_READINGS, require_builds, require_slave, running
from orfa import boardmap
from orfa.busio import I2C
from orfa.sim import SimBoard, sim_path
from orfa.smbus import SMBus

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs" / "sensors.md"
READINGS = ROOT / "build" / "sensor-readings.txt"
F_CPU = 7372800
G = 9.80665                              # m/s^2 per g, as the MPU-6050's driver has it

# 8-bit bus addresses (the parts, the slave) and their 7-bit forms (the drivers)
MPU, HMC, LIS, BMP_PIM, BMP_ADA, EE32, SLAVE8 = 0xD0, 0x3C, 0x38, 0xEC, 0xEE, 0xA8, 0x10
GATEWAY = 0x55                           # the gateway's own map (AA)
BASE_PARTS = [("mpu6050", MPU), ("hmc5883l", HMC), ("lis3mdl", LIS)]
LATER_PARTS = [("bmp280", BMP_PIM), ("bmp280", BMP_ADA), ("24lc32", EE32)]


def ms(t: float) -> int:
    """Simulated cycles in T milliseconds."""
    return int(F_CPU * t / 1000) + 1


def need(module: str, package: str):
    return pytest.importorskip(module, reason="%s is not installed (tools/setup.sh installs it)"
                               % package)


def raw(value: float, per_unit: float, lo: int = -32768, hi: int = 32767) -> int:
    """A register's code for VALUE at PER_UNIT LSB per unit: rounded to
    nearest (ties upward), saturated, as the parts report it."""
    return max(lo, min(hi, math.floor(value * per_unit + 0.5)))


# --- the readings table -----------------------------------------------------------------

def fmt(values) -> str:
    if isinstance(values, (tuple, list)):
        return ", ".join(fmt(v) for v in values)
    return "%.6g" % values


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

def sim_parts():
    # until orfa.sim.part_kinds (branch i18-baro) is on main
    import subprocess
    text = subprocess.run([str(sim_path()), "--help"], capture_output=True, text=True).stderr
    section = text.partition("Parts on the I2C bus")[2].partition("Parts on a board")[0]
    return [line.split()[0].split("[")[0] for line in section.splitlines()[1:] if line.strip()]


def parts_there():
    """The parts this robot carries: the sensor parts, and the barometers and
    the 24LC32 once the simulator has them."""
    kinds = sim_parts()
    return BASE_PARTS + [p for p in LATER_PARTS if p[0] in kinds]


def need_part(kind: str):
    if kind not in sim_parts():
        pytest.skip("orfa-sim has no %s part yet (--part %s@ADDR; the parts of issue 18)"
                    % (kind, kind))


@pytest.fixture(scope="module")
def robot():
    require_builds(["m32d"])
    elf = require_slave("m128s", SLAVE8)
    sim = SimBoard("m32d", trace=False, control=True, slaves=[("m128s", SLAVE8, elf)],
                   extra_args=[a for kind, addr in parts_there()
                               for a in ("--part", "%s@0x%02X" % (kind, addr))])
    with running(sim) as b:
        b.ctl = sim.control
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
    expected = sorted([SLAVE8 >> 1, GATEWAY] + [addr >> 1 for _, addr in parts_there()])
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
