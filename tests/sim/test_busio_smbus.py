"""orfa.busio.I2C and orfa.smbus.SMBus on a simulated robot's bus: an
M32-D gateway, an M128-S slave board at 0x10 (7-bit 0x08), a 24C02 EEPROM
at A0 (0x50), a write-protected one at A6 (0x53) and an SRF08 at E0
(0x70). The EEPROM written and read through both interfaces and through
Adafruit's I2CDevice, checked on the bus trace (one transaction, a
repeated START); a slave board's introspection through smbus and
adafruit_register; what a missing device and a refused byte raise, and
the errors Adafruit's and Pimoroni's drivers make of them when their
sensor is not there. The scripted line: tests/host/test_bus_interfaces.py."""

import errno
import subprocess

import pytest

from conftest import bench_running, for_each_test, require_builds, require_slave, running
from orfa import boardmap
from orfa.busio import I2C
from orfa.sim import SimBoard, sim_path
from orfa.smbus import SMBus

SLAVE, EEPROM, EEPROM_WP, SRF08 = 0x08, 0x50, 0x53, 0x70      # 7-bit
GATEWAY = 0x55                                                 # its own map (AA)
#: A part of the EEPROM no other test module's board shares.
AREA = 0x40


def need(module: str, package: str):
    return pytest.importorskip(module, reason="%s is not installed (tools/setup.sh installs it)"
                               % package)


@pytest.fixture(scope="module")
def robot_bench():
    yield from bench_running("m32d", eeproms=(EEPROM << 1,), srf08=(SRF08 << 1,), trace=True,
                             extra_args=("--eeprom", "0x%02X:wp" % (EEPROM_WP << 1)),
                             slaves=[("m128s", SLAVE << 1, require_slave("m128s", SLAVE << 1))])


@pytest.fixture
def bench(robot_bench):
    yield from for_each_test(robot_bench)


@pytest.fixture
def i2c(bench):
    bus = I2C(bench.gw)
    assert bus.try_lock()
    yield bus
    bus.deinit()
    assert bench.gw.serial.is_open                  # the bench's gateway stays open


def records(board: str) -> bytes:
    """A board's introspection records, from its map."""
    return b"".join(bytes([d.uid >> 8, d.uid & 0xFF, d.major, d.minor, d.start, d.count])
                    for d in boardmap.load(board).drivers)


# --- scan ------------------------------------------------------------------------------

def test_scan_finds_the_eeproms_the_slave_the_ranger_and_the_gateway(i2c):
    assert i2c.scan() == [SLAVE, EEPROM, EEPROM_WP, GATEWAY, SRF08]


# --- the EEPROM through busio ----------------------------------------------------------------

def test_busio_eeprom_write_and_read_back(bench, i2c):
    data = bytes([0xC0, 0x01, 0xFE, 0x55])
    mark = bench.mark()
    i2c.writeto(EEPROM, bytes([AREA]) + data)
    assert bench.bus(mark) == [("start",), ("addr", "A0", "ack"), ("write", "%02X" % AREA, "ack")] \
        + [("write", "%02X" % b, "ack") for b in data] + [("stop",)]
    buf = bytearray(4)
    mark = bench.mark()
    i2c.writeto_then_readfrom(EEPROM, bytes([AREA]), buf)
    assert buf == data
    # one transaction: a repeated START between the write and the read, one STOP
    assert bench.bus(mark) == [
        ("start",), ("addr", "A0", "ack"), ("write", "%02X" % AREA, "ack"),
        ("start",), ("addr", "A1", "ack"),
        ("read", "C0", "ack"), ("read", "01", "ack"), ("read", "FE", "ack"),
        ("read", "55", "nack"), ("stop",)]
    # the EEPROM's pointer is past the four: a plain read goes on from there
    i2c.writeto_then_readfrom(EEPROM, bytes([AREA + 2]), buf, in_end=1)
    i2c.readfrom_into(EEPROM, buf, start=1, end=2)
    assert buf[:2] == b"\xfe\x55"


def test_busio_same_buffer_and_slices_on_the_eeprom(i2c):
    i2c.writeto(EEPROM, bytes([0xEE, AREA + 8, 1, 2, 3, 0xEE]), start=1, end=-1)
    buf = bytearray([AREA + 8, 0, 0, 0])
    i2c.writeto_then_readfrom(EEPROM, buf, buf, out_end=1, in_start=1)
    assert buf == bytes([AREA + 8, 1, 2, 3])


def test_busio_missing_device_and_refused_byte(i2c):
    with pytest.raises(OSError) as e:
        i2c.writeto(0x51, b"")
    assert e.value.errno == errno.ENODEV
    with pytest.raises(OSError) as e:
        i2c.readfrom_into(0x51, bytearray(1))
    assert e.value.errno == errno.ENODEV
    # the write-protected 24C02 takes its word address, refuses the data
    with pytest.raises(OSError) as e:
        i2c.writeto(EEPROM_WP, bytes([0x00, 0x12]))
    assert e.value.errno == errno.EIO


def test_busio_longest_read_in_one_request(bench, i2c):
    """60 bytes after a register byte: the reply's 126 characters fit, and
    the device sees one read of 60 bytes."""
    buf = bytearray(60)
    mark = bench.mark()
    i2c.writeto_then_readfrom(EEPROM, b"\x00", buf)
    reads = [e for e in bench.bus(mark) if e[0] == "read"]
    assert len(reads) == 60 and reads[-1][2] == "nack"
    assert [e for e in bench.bus(mark) if e[0] in ("start", "stop")] == \
        [("start",), ("start",), ("stop",)]
    with pytest.raises(ValueError, match="reads at most 60 after 1 written"):
        i2c.writeto_then_readfrom(EEPROM, b"\x00", bytearray(61))


# --- Adafruit's own classes -------------------------------------------------------------------

def test_adafruit_i2cdevice_on_the_eeprom(i2c):
    I2CDevice = need("adafruit_bus_device.i2c_device", "adafruit-circuitpython-busdevice").I2CDevice
    i2c.unlock()
    with pytest.raises(ValueError, match="No I2C device at address: 0x51"):
        I2CDevice(i2c, 0x51)
    device = I2CDevice(i2c, EEPROM)
    with device:
        device.write(bytes([AREA + 16, 0x11, 0x22, 0x33]))
    buf = bytearray([AREA + 16, 0, 0, 0])
    with device:
        device.write_then_readinto(buf, buf, out_end=1, in_start=1)
    assert buf == bytes([AREA + 16, 0x11, 0x22, 0x33])


def test_adafruit_register_reads_a_slave_boards_introspection(bench, i2c):
    """An ORFA slave is an I2C device too: adafruit_register's UnaryStruct
    (register byte, repeated START, read into the same buffer) reads its
    driver count and status; writing an index to the count register
    selects what it reads (0: the count, N: record N; docs/registers.md)."""
    I2CDevice = need("adafruit_bus_device.i2c_device", "adafruit-circuitpython-busdevice").I2CDevice
    UnaryStruct = need("adafruit_register.i2c_struct", "adafruit-circuitpython-register").UnaryStruct

    class Introspection:
        count = UnaryStruct(0x00, "<B")
        status = UnaryStruct(0x01, "<B")

        def __init__(self, bus, address):
            self.i2c_device = I2CDevice(bus, address)

    i2c.unlock()
    intro = Introspection(i2c, SLAVE)
    intro.count = 0                                 # write 00 00: the count selected
    assert intro.count == len(boardmap.load("m128s").drivers)
    assert intro.status == 0
    intro.count = 2                                 # record 2 selected
    buf = bytearray(6)
    i2c.try_lock()
    i2c.readfrom_into(SLAVE, buf)
    assert bytes(buf) == records("m128s")[6:12]


@pytest.mark.parametrize("module, package, make, address", [
    ("adafruit_mpu6050", "adafruit-circuitpython-mpu6050", lambda m, i2c: m.MPU6050(i2c), 0x68),
    ("adafruit_lis3mdl", "adafruit-circuitpython-lis3mdl", lambda m, i2c: m.LIS3MDL(i2c), 0x1C),
    ("adafruit_bmp280", "adafruit-circuitpython-bmp280",
     lambda m, i2c: m.Adafruit_BMP280_I2C(i2c), 0x77),
])
def test_adafruit_drivers_find_no_sensor_on_this_bus(i2c, module, package, make, address):
    """No such sensor on this robot's bus: each driver's own error, from
    the I2CDevice probe's OSErrors."""
    driver = need(module, package)
    i2c.unlock()
    with pytest.raises(ValueError, match="No I2C device at address: 0x%x$" % address):
        make(driver, i2c)


def test_pimoroni_bmp280_finds_no_sensor_on_this_bus(bench):
    """Pimoroni's driver takes the SMBus as i2c_dev; no BMP280 at 0x76:
    its own error, from the OSError of the register read."""
    BMP280 = need("bmp280", "bmp280").BMP280
    with SMBus(bench.gw) as bus:
        with pytest.raises(RuntimeError, match="Unable to find bmp280 on 0x76, IOError"):
            BMP280(i2c_dev=bus).setup()


def test_adafruit_24lc32():
    """Adafruit's 24LC32 driver on the simulator's 24lc32 part at A8 (7-bit
    0x54): two-byte word addresses, written byte by byte, read back in one
    request."""
    EEPROM_I2C = need("adafruit_24lc32", "adafruit-circuitpython-24lc32").EEPROM_I2C
    require_builds(["m32d"])
    r = subprocess.run([str(sim_path()), "--help"], capture_output=True, text=True)
    usage = r.stdout + r.stderr
    assert "eeprom24" in usage, usage                   # the list of parts is where it is looked for
    if "24lc32" not in usage:
        pytest.skip("orfa-sim has no 24lc32 part yet (--part 24lc32@0xA8; the parts of issue 18)")
    sim = SimBoard("m32d", trace=False, extra_args=("--part", "24lc32@0xA8"))
    with running(sim) as b, I2C(b.gw) as i2c:
        eeprom = EEPROM_I2C(i2c, address=0x54)
        assert len(eeprom) == 4096
        eeprom[0x0FFC] = 0x5A
        eeprom[0x0123:0x0126] = [1, 2, 3]
        assert eeprom[0x0FFC] == b"\x5a"
        assert eeprom[0x0123:0x0126] == b"\x01\x02\x03"


def test_a_port_opens_its_own_gateway():
    """I2C and SMBus given the simulator's link, as a real port's path:
    each opens the port, syncs, and closes it at the end."""
    require_builds(["m32d"])
    with SimBoard("m32d", eeproms=(EEPROM << 1,), trace=False) as sim:
        with I2C(sim.port) as i2c:
            assert i2c.try_lock()
            i2c.writeto(EEPROM, bytes([AREA + 40, 0x3C, 0xC3]))
            gateway = i2c.gateway
        assert not gateway.serial.is_open
        with SMBus(sim.port) as bus:
            assert bus.read_i2c_block_data(EEPROM, AREA + 40, 2) == [0x3C, 0xC3]
            gateway = bus.gateway
        assert not gateway.serial.is_open
        assert sim.stop() == 0


# --- smbus2's SMBus -----------------------------------------------------------------------------

def test_smbus_eeprom(bench):
    with SMBus(bench.gw) as bus:
        bus.write_i2c_block_data(EEPROM, AREA + 24, [0xA5, 0x5A, 0x0F])
        assert bus.read_i2c_block_data(EEPROM, AREA + 24, 3) == [0xA5, 0x5A, 0x0F]
        bus.write_byte_data(EEPROM, AREA + 28, 0x42)
        assert bus.read_byte_data(EEPROM, AREA + 28) == 0x42
        bus.write_word_data(EEPROM, AREA + 30, 0xBEEF)          # EF, then BE
        assert bus.read_i2c_block_data(EEPROM, AREA + 30, 2) == [0xEF, 0xBE]
        assert bus.read_word_data(EEPROM, AREA + 30) == 0xBEEF
        bus.write_byte(EEPROM, AREA + 24)                       # the word address alone
        assert bus.read_byte(EEPROM) == 0xA5
        assert bus.read_byte(EEPROM) == 0x5A
        bus.write_quick(EEPROM)


def test_smbus_slave_introspection(bench):
    """The slave board's driver count by write_byte_data (index 0: the
    count) and read_i2c_block_data, its records by i2c_rdwr (write [00 01], repeated START, read them all), as the
    board map has them."""
    i2c_msg = need("smbus2", "smbus2").i2c_msg
    recs = records("m128s")
    with SMBus(bench.gw) as bus:
        bus.write_byte_data(SLAVE, 0x00, 0x00)                  # the count selected
        assert bus.read_i2c_block_data(SLAVE, 0x00, 1) == [len(recs) // 6]
        w, r = i2c_msg.write(SLAVE, [0x00, 0x01]), i2c_msg.read(SLAVE, len(recs))
        bus.i2c_rdwr(w, r)
        assert bytes(r) == recs
        # the gateway's own map answers at its local address the same way
        bus.write_byte_data(GATEWAY, 0x00, 0x00)
        assert bus.read_i2c_block_data(GATEWAY, 0x00, 1) == \
            [len(boardmap.load("m32d").drivers)]


def test_smbus_missing_device_and_refused_byte(bench):
    with SMBus(bench.gw) as bus:
        with pytest.raises(OSError) as e:
            bus.read_byte_data(0x51, 0x00)
        assert e.value.errno == errno.ENXIO
        with pytest.raises(OSError) as e:
            bus.write_byte_data(EEPROM_WP, 0x00, 0x12)
        assert e.value.errno == errno.EIO
        bus.write_byte_data(EEPROM, AREA + 29, 0x24)            # and the bus goes on
        assert bus.read_byte_data(EEPROM, AREA + 29) == 0x24


# --- docs/sensors.md ----------------------------------------------------------------------------

def test_docs_examples_print_what_the_docs_show(capsys):
    """docs/sensors.md's runnable examples (the simulated ones, each
    followed by "prints"), run: each prints what the page says."""
    import re
    from pathlib import Path
    need("adafruit_bus_device.i2c_device", "adafruit-circuitpython-busdevice")
    need("smbus2", "smbus2")
    require_builds(["m32d"])
    require_slave("m128s", SLAVE << 1)
    text = (Path(__file__).resolve().parents[2] / "docs" / "sensors.md").read_text()
    examples = re.findall(r"```python\n((?:(?!```).)*)```\n\nprints\n\n```\n(.*?)```", text, re.S)
    assert len(examples) == 2
    for code, shown in examples:
        exec(compile(code, "docs/sensors.md", "exec"), {})
        assert capsys.readouterr().out == shown


# --- the fast rates ---------------------------------------------------------------------

@pytest.mark.parametrize("board, rate", [("m32d", 460800), ("m128s", 230400)])
def test_smbus_and_busio_at_a_fast_rate(board, rate):
    """SMBus and busio.I2C opened on a port with baudrate= the gateway's
    BAUD (460800, 230400): an MPU-6050's WHO_AM_I and its 14-byte burst,
    as a robot program reads them."""
    from conftest import build_gateway
    require_builds([board])
    with SimBoard(board, firmware=build_gateway(board, rate), trace=False,
                  parts=[("mpu6050", 0xD0)]) as sim:
        port = sim.port
        with SMBus(port, baudrate=rate) as bus:
            assert bus.gateway.serial.baudrate == rate
            assert bus.read_byte_data(0x68, 0x75) == 0x68
            assert len(bus.read_i2c_block_data(0x68, 0x3B, 14)) == 14
        i2c = I2C(port, baudrate=rate)
        try:
            assert i2c.try_lock()
            assert i2c.scan() == [0x55, 0x68]
            burst = bytearray(14)
            i2c.writeto_then_readfrom(0x68, bytes([0x3B]), burst)
            who = bytearray(1)
            i2c.writeto_then_readfrom(0x68, bytes([0x75]), who)
            assert who == b"\x68"
        finally:
            i2c.deinit()
