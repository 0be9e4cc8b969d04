"""orfa.busio.I2C and orfa.smbus.SMBus on a scripted gateway
(fake_line.FakeLine): the exact request each call sends, what the reply
becomes, the OSErrors of refusals, buffer slices, the same buffer in and
out, and the limits of one request. The simulated bus: tests/sim/test_busio_smbus.py."""

import errno

import pytest

from fake_line import FakeLine, synced_gateway
from orfa import MAX_REPLY_CHARS, MAX_REQUEST_CHARS
from orfa.busio import I2C
from orfa.smbus import SMBus

try:
    from smbus2 import i2c_msg
except ImportError:
    i2c_msg = None
needs_smbus2 = pytest.mark.skipif(i2c_msg is None, reason="smbus2 is not installed"
                                  " (tools/setup.sh installs it)")

#: A 24C02-like EEPROM at 7-bit 0x50 (A0) that holds 01 02 03 04 from word
#: address 10; nothing at 0x51 (A2); a device at 0x52 (A4) that refuses data.
TABLE = {
    "SA0P": "SWP", "SA2P": "ERROR 06", "SA301P": "ERROR 06", "SA4P": "SWP",
    "SA0100102P": "SWAAAP", "SA103P": "SR010203P", "SA010SA104P": "SWASR01020304P",
    "SA40155P": "ERROR 07", "SA2AAP": "ERROR 06",
}


def answers(table):
    def answer(line):
        if line in table:
            return table[line]
        return {"V": "V1.1", "C": "C0063", "C0190": "C0170"}.get(line, "ERROR 02")
    return answer


@pytest.fixture
def fake(monkeypatch):
    """fake(table) -> (Gateway, FakeLine): the opening sync done and left
    out of line.written; requests the table lacks answer ERROR 02."""
    def make(table=TABLE):
        line = FakeLine(answers(table))
        return synced_gateway(monkeypatch, line), line
    return make


@pytest.fixture
def i2c(fake):
    gw, line = fake()
    bus = I2C(gw)
    assert bus.try_lock()
    return bus, line


# --- busio.I2C: requests ---------------------------------------------------------------

def test_busio_requests(i2c):
    bus, line = i2c
    bus.writeto(0x50, bytes([0x10, 0x01, 0x02]))
    buf = bytearray(3)
    bus.readfrom_into(0x50, buf)
    assert buf == b"\x01\x02\x03"
    buf = bytearray(4)
    bus.writeto_then_readfrom(0x50, b"\x10", buf)
    assert buf == b"\x01\x02\x03\x04"
    bus.writeto(0x50, b"")                              # the probe: address alone
    assert line.written == ["SA0100102P", "SA103P", "SA010SA104P", "SA0P"]


def test_busio_scan(fake):
    present = {0x08, 0x50, 0x77}
    gw, line = fake({"S%02XP" % (a << 1): "SWP" if a in present else "ERROR 06"
                     for a in range(0x08, 0x78)})
    bus = I2C(gw)
    assert bus.try_lock()
    assert bus.scan() == [0x08, 0x50, 0x77]
    # pipelined; the V marker after them checks the ERROR replies were theirs
    assert line.written == ["S%02XP" % (a << 1) for a in range(0x08, 0x78)] + ["V"]


def test_busio_slices(i2c):
    """start/end slice the buffers as buf[start:end], negative ends too;
    a read fills only its slice."""
    bus, line = i2c
    bus.writeto(0x50, b"\xff\x10\x01\x02\xff", start=1, end=4)
    bus.writeto(0x50, bytearray(b"\xee\x10\x01\x02"), start=-3)
    buf = bytearray(b"\xaa" * 6)
    bus.readfrom_into(0x50, buf, start=2, end=5)
    assert buf == b"\xaa\xaa\x01\x02\x03\xaa"
    buf = bytearray(b"\xaa" * 5)
    bus.writeto_then_readfrom(0x50, b"\x00\x10\x00", buf, out_start=1, out_end=2, in_start=1)
    assert buf == b"\xaa\x01\x02\x03\x04"
    assert line.written == ["SA0100102P", "SA0100102P", "SA103P", "SA010SA104P"]


def test_busio_same_buffer_in_and_out(i2c):
    """adafruit_register's pattern: the register byte in buf[0], the
    reply read into buf[1:]; and a read over the byte it wrote."""
    bus, line = i2c
    buf = bytearray([0x10, 0, 0, 0, 0])
    bus.writeto_then_readfrom(0x50, buf, buf, out_end=1, in_start=1)
    assert buf == b"\x10\x01\x02\x03\x04"
    buf = bytearray([0x10, 0xFF, 0xFF, 0xFF])
    bus.writeto_then_readfrom(0x50, buf, buf, out_end=1)
    assert buf == b"\x01\x02\x03\x04"
    assert line.written == ["SA010SA104P", "SA010SA104P"]


def test_busio_errors(i2c):
    """ERROR 06: ENODEV; ERROR 07: EIO; args[0] is the errno as
    CircuitPython's OSError has it."""
    bus, line = i2c
    with pytest.raises(OSError) as e:
        bus.writeto(0x51, b"")
    assert e.value.errno == errno.ENODEV and e.value.args[0] == errno.ENODEV
    assert "0x51" in str(e.value) and "ERROR 06" in str(e.value)
    with pytest.raises(OSError) as e:
        bus.writeto(0x52, b"\x01\x55")
    assert e.value.errno == errno.EIO and "ERROR 07" in str(e.value)
    # each ERROR reply is followed by the gateway's V marker (Gateway.run)
    assert line.written == ["SA2P", "V", "SA40155P", "V"]


def test_busio_silent_gateway_is_etimedout(fake):
    gw, line = fake()
    line.answer = lambda text: None
    bus = I2C(gw)
    bus.try_lock()
    with pytest.raises(OSError) as e:
        bus.writeto(0x50, b"\x10")
    assert e.value.errno == errno.ETIMEDOUT and "no reply from the ORFA gateway" in str(e.value)


def test_busio_i2cdevice_probe(i2c):
    """Adafruit's I2CDevice probes with an empty write, then a one-byte
    read; both refused: its own ValueError."""
    I2CDevice = pytest.importorskip(
        "adafruit_bus_device.i2c_device",
        reason="adafruit-circuitpython-busdevice is not installed (tools/setup.sh installs it)"
    ).I2CDevice
    bus, line = i2c
    bus.unlock()
    with pytest.raises(ValueError, match="No I2C device at address: 0x51"):
        I2CDevice(bus, 0x51)
    assert line.written == ["SA2P", "V", "SA301P", "V"]
    del line.written[:]
    device = I2CDevice(bus, 0x50)
    buf = bytearray([0x10, 0, 0, 0, 0])
    with device:
        device.write_then_readinto(buf, buf, out_end=1, in_start=1)
    assert buf == b"\x10\x01\x02\x03\x04"
    assert line.written == ["SA0P", "SA010SA104P"]


def test_busio_lock_and_deinit(fake):
    gw, line = fake()
    bus = I2C(gw)
    with pytest.raises(RuntimeError, match="Function requires lock"):
        bus.writeto(0x50, b"")
    with pytest.raises(RuntimeError, match="Function requires lock"):
        bus.scan()
    assert bus.try_lock() is True
    assert bus.try_lock() is False
    bus.unlock()
    bus.unlock()
    assert bus.try_lock() is True
    with bus:
        pass
    with pytest.raises(ValueError, match="deinitialized"):
        bus.try_lock()
    with pytest.raises(ValueError, match="deinitialized"):
        bus.writeto(0x50, b"")
    bus.deinit()
    assert line.is_open                                 # the caller's gateway stays open
    assert line.written == []


def test_busio_opens_and_closes_its_own_port(fake):
    _, line = fake()
    with I2C("fake://", frequency=400000) as bus:
        assert bus.gateway.url == "fake://"
    assert not line.is_open
    assert line.written[-1] == "C0190"                  # 400 kHz asked: the C request


@pytest.mark.parametrize("call, message", [
    (lambda b: b.writeto(0x80, b""), "7-bit"),
    (lambda b: b.writeto(-1, b""), "7-bit"),
    (lambda b: b.readfrom_into(0x50, bytearray(0)), "at least length 1"),
    (lambda b: b.readfrom_into(0x50, bytearray(4), start=4), "at least length 1"),
    (lambda b: b.writeto_then_readfrom(0x50, b"\x10", bytearray(2), in_start=2),
     "at least length 1"),
])
def test_busio_bad_arguments(i2c, call, message):
    bus, line = i2c
    with pytest.raises(ValueError, match=message):
        call(bus)
    assert line.written == []


def test_busio_read_into_bytes_is_refused(i2c):
    bus, line = i2c
    with pytest.raises(TypeError, match="writable"):
        bus.readfrom_into(0x50, bytes(3))
    assert line.written == []


def test_busio_frequency_is_checked(fake):
    gw, line = fake()
    with pytest.raises(ValueError, match="frequency is 1000..65535000 Hz"):
        I2C(gw, frequency=999)
    assert line.written == []


# --- the limits of one request -------------------------------------------------------

@pytest.mark.parametrize("call, request_chars, reply_chars", [
    (lambda b: b.writeto(0x50, bytes(62)), MAX_REQUEST_CHARS, 65),
    (lambda b: b.readfrom_into(0x50, bytearray(62)), 6, MAX_REPLY_CHARS),
    (lambda b: b.writeto_then_readfrom(0x50, bytes(59), bytearray(31)), 127, 126),
    (lambda b: b.writeto_then_readfrom(0x50, b"\x10", bytearray(60)), 11, 126),
    (lambda b: b.writeto_then_readfrom(0x50, b"\x10\x00", bytearray(60)), 13, MAX_REPLY_CHARS),
    (lambda b: b.writeto_then_readfrom(0x50, b"", bytearray(61)), 9, MAX_REPLY_CHARS),
])
def test_busio_longest_transfers_go_as_one_request(fake, call, request_chars, reply_chars):
    gw, line = fake({})
    line.answer = device_answer
    bus = I2C(gw)
    bus.try_lock()
    call(bus)
    (request,) = line.written
    assert len(request) == request_chars
    assert len(device_answer(request)) == reply_chars


@pytest.mark.parametrize("call, message", [
    (lambda b: b.writeto(0x50, bytes(63)),
     "writeto of 63 bytes needs a request of 130 characters .the limit is 128.: one ORFA"
     " request writes at most 62 bytes"),
    (lambda b: b.readfrom_into(0x50, bytearray(63)),
     "readfrom_into of 63 bytes needs a reply of 129 characters .the limit is 127.: one ORFA"
     " request reads at most 62 bytes"),
    (lambda b: b.readfrom_into(0x50, bytearray(300)), "reads at most 62 bytes"),
    (lambda b: b.writeto_then_readfrom(0x50, bytes(60), bytearray(1)),
     "request of 129 characters .* writes at most 59 bytes before a read"),
    (lambda b: b.writeto_then_readfrom(0x50, b"\x10", bytearray(61)),
     "reply of 128 characters .* reads at most 60 after 1 written"),
])
def test_busio_over_the_limit_is_refused_whole(i2c, call, message):
    """A ValueError that names the limit; nothing is sent (never split)."""
    bus, line = i2c
    with pytest.raises(ValueError, match=message) as e:
        call(bus)
    assert "docs/sensors.md" in str(e.value)
    assert line.written == []


def device_answer(line):
    """What a device that acknowledges everything answers to a compact
    transaction request (reads give 00s)."""
    out, i = "", 0
    body = line[:-1]
    while i < len(body):
        assert body[i] == "S", line
        addr = int(body[i + 1:i + 3], 16)
        j = body.find("S", i + 3)
        j = len(body) if j < 0 else j
        if addr & 1:
            out += "SR" + "00" * int(body[i + 3:j], 16)
        else:
            out += "SW" + "A" * ((j - i - 3) // 2)
        i = j
    return out + "P"


# --- smbus2's SMBus -----------------------------------------------------------------------

SMBUS_TABLE = dict(TABLE, **{
    "SA101P": "SR5AP", "SA07FP": "SWAP", "SA010SA101P": "SWASR5AP", "SA01055P": "SWAAP",
    "SA010SA102P": "SWASR3412P", "SA0103412P": "SWAAAP",
    "SA0103412SA102P": "SWAAASR7856P", "SA010SA121P": "SWASR03010203" + "EE" * 29 + "P",
    "SA01003010203P": "SWAAAAAP", "SA01002AABBSA121P": "SWAAAASR02CCDD" + "00" * 30 + "P",
    "SA0100A0BP": "SWAAAP", "SA020SA121P": "SWASR21" + "00" * 32 + "P",
    "SA00001SA10CP": "SWAASR000001000002002001000204P",
})


@pytest.fixture
def smbus(fake):
    gw, line = fake(SMBUS_TABLE)
    return SMBus(gw), line


@pytest.mark.parametrize("call, sent, result", [
    (lambda b: b.write_quick(0x50), "SA0P", None),
    (lambda b: b.read_byte(0x50), "SA101P", 0x5A),
    (lambda b: b.write_byte(0x50, 0x7F), "SA07FP", None),
    (lambda b: b.read_byte_data(0x50, 0x10), "SA010SA101P", 0x5A),
    (lambda b: b.write_byte_data(0x50, 0x10, 0x55), "SA01055P", None),
    (lambda b: b.read_word_data(0x50, 0x10), "SA010SA102P", 0x1234),      # low byte first
    (lambda b: b.write_word_data(0x50, 0x10, 0x1234), "SA0103412P", None),
    (lambda b: b.process_call(0x50, 0x10, 0x1234), "SA0103412SA102P", 0x5678),
    (lambda b: b.read_block_data(0x50, 0x10), "SA010SA121P", [1, 2, 3]),
    (lambda b: b.write_block_data(0x50, 0x10, [1, 2, 3]), "SA01003010203P", None),
    (lambda b: b.block_process_call(0x50, 0x10, [0xAA, 0xBB]), "SA01002AABBSA121P",
     [0xCC, 0xDD]),
    (lambda b: b.read_i2c_block_data(0x50, 0x10, 4), "SA010SA104P", [1, 2, 3, 4]),
    (lambda b: b.write_i2c_block_data(0x50, 0x10, [0x0A, 0x0B]), "SA0100A0BP", None),
])
def test_smbus_requests(smbus, call, sent, result):
    bus, line = smbus
    assert call(bus) == result
    assert line.written == [sent]


@needs_smbus2
def test_smbus_i2c_rdwr_with_smbus2_messages(smbus):
    """One transaction: write [00 01] (introspection, driver 1), repeated
    START, read 12 bytes into the read message's own buffer."""
    bus, line = smbus
    w, r = i2c_msg.write(0x50, [0x00, 0x01]), i2c_msg.read(0x50, 12)
    assert bus.i2c_rdwr(w, r) is None
    assert bytes(r) == bytes.fromhex("000001000002002001000204") and list(r)[:3] == [0, 0, 1]
    assert line.written == ["SA00001SA10CP"]


def test_smbus_errors(smbus):
    """Linux's fault codes: ENXIO for no ACK of the address, EIO for a
    refused byte, EPROTO for a block count over 32."""
    bus, line = smbus
    with pytest.raises(OSError) as e:
        bus.read_byte(0x51)
    assert e.value.errno == errno.ENXIO and "0x51" in str(e.value)
    with pytest.raises(OSError) as e:
        bus.write_byte_data(0x52, 0x01, 0x55)
    assert e.value.errno == errno.EIO
    with pytest.raises(OSError) as e:
        bus.read_block_data(0x50, 0x20)
    assert e.value.errno == errno.EPROTO and "33" in str(e.value)
    assert line.written == ["SA301P", "V", "SA40155P", "V", "SA020SA121P"]


def test_smbus_silent_gateway_is_etimedout(fake):
    gw, line = fake()
    line.answer = lambda text: None
    with pytest.raises(OSError) as e:
        SMBus(gw).read_byte(0x50)
    assert e.value.errno == errno.ETIMEDOUT


@needs_smbus2
@pytest.mark.parametrize("call, error, message", [
    (lambda b: b.read_i2c_block_data(0x50, 0x10, 33), ValueError,
     "Desired block length over 32 bytes"),
    (lambda b: b.read_i2c_block_data(0x50, 0x10, 0), ValueError, "1..32 bytes"),
    (lambda b: b.write_i2c_block_data(0x50, 0x10, [0] * 33), ValueError,
     "Data length cannot exceed 32 bytes"),
    (lambda b: b.write_block_data(0x50, 0x10, [0] * 33), ValueError,
     "Data length cannot exceed 32 bytes"),
    (lambda b: b.block_process_call(0x50, 0x10, [0] * 33), ValueError,
     "Data length cannot exceed 32 bytes"),
    (lambda b: b.write_byte_data(0x50, 0x10, 256), ValueError, "value is a byte"),
    (lambda b: b.write_word_data(0x50, 0x10, 0x10000), ValueError, "0..65535"),
    (lambda b: b.read_byte(0x80), ValueError, "7-bit"),
    (lambda b: b.i2c_rdwr(), ValueError, "at least one i2c_msg"),
    (lambda b: b.i2c_rdwr(i2c_msg.write(0x50, bytes(63))), ValueError,
     "i2c_rdwr with 1 i2c_msg needs a request of 130 characters .the limit is 128."),
    (lambda b: b.i2c_rdwr(i2c_msg.write(0x50, bytes(40)), i2c_msg.read(0x50, 50)),
     ValueError, "needs a reply of 145 characters"),
    (lambda b: b.i2c_rdwr(i2c_msg.write(0x50, [1]), i2c_msg.read(0x50, 61)), ValueError,
     "needs a reply of 128 characters .the limit is 127."),
])
def test_smbus_refusals_send_nothing(smbus, call, error, message):
    bus, line = smbus
    with pytest.raises(error, match=message):
        call(bus)
    assert line.written == []


@needs_smbus2
def test_smbus_i2c_rdwr_unsupported_flags(smbus):
    bus, line = smbus
    ten_bit = i2c_msg.write(0x50, [1])
    ten_bit.flags = 0x0010                              # I2C_M_TEN
    with pytest.raises(OSError) as e:
        bus.i2c_rdwr(ten_bit)
    assert e.value.errno == errno.EOPNOTSUPP and "0x0010" in str(e.value)
    assert line.written == []


def test_smbus_open_and_close(fake):
    gw, line = fake(SMBUS_TABLE)
    with pytest.raises(TypeError, match="not the bus number 1"):
        SMBus(1)
    with SMBus(gw) as bus:
        assert bus.gateway is gw
    with pytest.raises(OSError) as e:
        bus.read_byte(0x50)
    assert e.value.errno == errno.EBADF
    assert line.is_open                                 # the caller's gateway stays open
    bus = SMBus()
    bus.open("fake://")
    assert bus.read_byte_data(0x50, 0x10) == 0x5A
    bus.close()
    assert not line.is_open


# --- Adafruit's 24LC32 driver on a scripted 24LC32 ------------------------------------------

class Eeprom24lc32:
    """A 4 KB EEPROM at A8 with two-byte word addresses, as a scripted
    gateway answers for it (compact transaction requests only)."""

    def __init__(self):
        self.mem = bytearray(b"\xff" * 4096)

    def __call__(self, line):
        if line in ("V", "C"):
            return {"V": "V1.1", "C": "C0063"}[line]
        if line == "SA8P":
            return "SWP"
        if line.startswith("SA8") and "S" not in line[1:-1]:          # a write
            data = bytes.fromhex(line[3:-1])
            at = (data[0] << 8 | data[1]) & 0xFFF
            self.mem[at:at + len(data) - 2] = data[2:]
            return "SW" + "A" * len(data) + "P"
        if line.startswith("SA8") and line[7:10] == "SA9":            # address, then read
            at, n = int(line[3:7], 16) & 0xFFF, int(line[10:12], 16)
            return "SWAASR" + self.mem[at:at + n].hex().upper() + "P"
        return "ERROR 06"


def test_adafruit_24lc32_on_a_scripted_eeprom(fake):
    """Adafruit's driver unchanged: a byte written per request with its
    two-byte word address, a slice read in one request, a slice over the
    limit refused."""
    EEPROM_I2C = pytest.importorskip(
        "adafruit_24lc32", reason="adafruit-circuitpython-24lc32 is not installed"
        " (tools/setup.sh installs it)").EEPROM_I2C
    gw, line = fake()
    line.answer = Eeprom24lc32()
    eeprom = EEPROM_I2C(I2C(gw), address=0x54)
    eeprom[0x0123:0x0126] = [1, 2, 3]
    assert eeprom[0x0122:0x0127] == b"\xff\x01\x02\x03\xff"
    # the probe; the driver reads the slice first (it writes only what
    # differs), then one byte per request; the read back
    assert line.written == ["SA8P", "SA80123SA903P", "SA8012301P", "SA8012402P", "SA8012503P",
                            "SA80122SA905P"]
    with pytest.raises(ValueError, match="reads at most 60 after 2 written"):
        eeprom[0:61]
