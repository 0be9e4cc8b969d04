"""`orfa` servo, motor, adc, gpio, spi and status against one simulated
robot (M32-D gateway with a 25-series EEPROM on SPI at PC2, analog inputs
preset; an M128-S slave at 0x10), checked on the pins through the control
socket, in simulated time."""


import pytest

from conftest import WIDTH_TOL, SERVO_FRAME, cli_runner, require_builds, us_to_cycles
from orfa import boardmap
from orfa.sim import SimRobot

M32D = boardmap.load("m32d")


def pin_of(function, index):
    (pin,) = M32D.pins_of(function, index)
    return pin.signal


@pytest.fixture(scope="module")
def robot():
    require_builds()
    with SimRobot("m32d", trace=False, control=True, spi=["eeprom25@C2"],
                  adc={6: 1200, 7: 4000}, slaves=[("m128s", 0x10, None)]) as sim:
        yield sim


@pytest.fixture
def orfa(robot, capsys, monkeypatch):
    """orfa(*argv) on the robot's port: (exit status, stdout, stderr)."""
    return cli_runner(robot.port, capsys, monkeypatch)


def pulse_width(sim, signal):
    """The high time of `signal` in cycles, over 5 frames once new widths run."""
    ctl = sim.control
    ctl.wait(2 * SERVO_FRAME + 8192)
    since = ctl.time()
    ctl.wait(5 * SERVO_FRAME)
    m = ctl.measure(signal, since=since)
    assert "high" in m, m
    lo, hi, _ = m["high"]
    return lo, hi


def test_servo_width_on_the_pin(orfa, robot):
    assert orfa("servo", "3", "1500") == (0, "", "")
    lo, hi = pulse_width(robot, "servo3")
    assert abs(lo - us_to_cycles(1500)) <= WIDTH_TOL and abs(hi - us_to_cycles(1500)) <= WIDTH_TOL
    assert orfa("servo", "3") == (0, "1500\n", "")
    assert orfa("servo", "3", "--angle") == (0, "0.0\n", "")


def test_servo_angle(orfa, robot):
    # the manual's formula over 1000..2000 us = -75..75 degrees: 30 degrees is 1700 us
    assert orfa("servo", "3", "--angle", "30") == (0, "", "")
    assert orfa("servo", "3") == (0, "1700\n", "")
    lo, hi = pulse_width(robot, "servo3")
    assert abs(lo - us_to_cycles(1700)) <= WIDTH_TOL and abs(hi - us_to_cycles(1700)) <= WIDTH_TOL
    assert orfa("servo", "3", "--angle", "--range", "500:2500:0:180") == (0, "108.0\n", "")
    assert orfa("servo", "3", "--angle", "80") == (
        2, "", "orfa: 80 degrees is outside the servo's -75..75\n")


def test_servo_table_and_off(orfa, robot):
    assert orfa("servo", "5", "2000") == (0, "", "")
    status, out, err = orfa("servo")
    assert out.splitlines()[:7] == ["channel  us", "0        off", "1        off",
                                     "2        off", "3        1700", "4        off",
                                     "5        2000"]
    assert len(out.splitlines()) == 1 + M32D.servo_channels
    assert orfa("servo", "5", "off") == (0, "", "")
    assert orfa("servo", "5") == (0, "off\n", "")
    assert orfa("servo", "off") == (0, "", "")
    assert orfa("servo", "3") == (0, "off\n", "")
    robot.control.wait(2 * SERVO_FRAME)
    since = robot.control.time()
    robot.control.wait(2 * SERVO_FRAME)
    assert robot.control.edges("servo3", since) == []


@pytest.mark.parametrize("argv, message", [
    (["servo", "16", "1500"], "orfa: channel 16: this board's channels are 0..15\n"),
    (["servo", "3", "3000"], "orfa: 3000 us: a width is 500..2500 us (0 or off: no pulses)\n"),
    (["servo", "x"], "orfa: channel 'x': a number 0..15 (or off)\n"),
    (["motor", "3", "10"], "orfa: motor '3': 1..2 (or stop)\n"),
    (["motor", "1", "256"], "orfa: duty '256': -255..255 (sign = direction, 0 or stop: stop)\n"),
    (["gpio", "E"], "orfa: port 'E': this board's GPIO ports are A, B, C, D\n"),
])
def test_bad_values_are_usage_errors(orfa, argv, message):
    assert orfa(*argv) == (2, "", message)


def test_servo_on_a_slave(orfa, robot):
    assert orfa("--addr", "0x10", "servo", "20", "1200") == (0, "", "")
    lo, hi = pulse_width(robot, "10/servo20")
    assert abs(lo - us_to_cycles(1200)) <= WIDTH_TOL
    assert orfa("servo", "--addr", "0x10", "20") == (0, "1200\n", "")
    assert orfa("--addr", "0x10", "servo", "off") == (0, "", "")


def test_motor(orfa, robot):
    assert orfa("motor", "1", "-128") == (0, "", "")
    assert orfa("motor", "2", "255") == (0, "", "")
    assert orfa("motor") == (0, "motor  duty\n1      -128\n2      255\n", "")
    assert orfa("motor", "1") == (0, "-128\n", "")
    ctl = robot.control
    ctl.wait(10000)
    since = ctl.time()
    ctl.wait(20000)
    m = ctl.measure(pin_of("MOTOR_PWM", 0), since=since)
    assert abs(m["duty"] - 128 / 255) < 0.01, m
    assert ctl.pin(pin_of("MOTOR_DIR", 0)) == (1, "out")        # backward
    assert ctl.pin(pin_of("MOTOR_PWM", 1)) == (1, "out")        # 255: steady high
    assert ctl.pin(pin_of("MOTOR_DIR", 1)) == (0, "out")
    assert orfa("motor", "stop") == (0, "", "")
    assert orfa("motor") == (0, "motor  duty\n1      0\n2      0\n", "")


def test_a_refused_write_says_why(orfa):
    # PWM1 shares its pin with servo channel 14: while that pulses, the motor is refused
    assert orfa("servo", "14", "1500") == (0, "", "")
    assert orfa("motor", "1", "100") == (
        1, "", "orfa: 0xAA motor PWM1: write refused: PIN_BUSY (a pin the operation"
               " needs belongs to another function)\n")
    assert orfa("servo", "14", "off") == (0, "", "")


def test_a_driver_the_board_lacks(orfa):
    status, out, err = orfa("--addr", "0x10", "motor", "1", "10")
    assert (status, out) == (1, "")
    assert err.startswith("orfa: ") and "motor" in err and err.count("\n") == 1


ADC_TABLE = """reference avcc 5.000 V, 10 bits
ch  raw  volts
0   off
1   off
2   off
3   off
4   off
5   off
6   {0}  {1}
7   {2}  {3}
"""


def test_adc_table_from_simulated_millivolts(orfa, robot):
    # 1200 mV and 4000 mV against AVCC 5 V in 10 bits: 245 and 818
    assert orfa("adc", "--channels", "6,7") == (
        0, ADC_TABLE.format(245, "1.196", 818, "3.994"), "")
    robot.control.adc(6, 2500)
    robot.control.wait(73728)                 # 10 ms: the ADC's promise
    assert orfa("adc") == (0, ADC_TABLE.format(511, "2.495", 818, "3.994"), "")
    status, out, err = orfa("adc", "--watch", "0", "--count", "3")
    assert (status, err) == (0, "")
    assert out == "\n".join([ADC_TABLE.format(511, "2.495", 818, "3.994")] * 3)
    status, out, err = orfa("adc", "--channels", "7", "--ref", "internal", "--bits", "8")
    assert out.splitlines()[0] == "reference internal 2.560 V, 8 bits"
    # 4000 mV is above the 2.56 V reference: full scale
    assert out.splitlines()[-1] == "7   255  2.550"
    assert orfa("adc", "--channels", "none")[0] == 0


def test_gpio(orfa, robot):
    # port C: PC0/PC1 are the TWI's, PC2 the SPI chip select of test_spi; 3 and 4 are free
    ctl = robot.control
    assert orfa("gpio", "C", "0x08", "--output", "0x18") == (0, "", "")
    assert ctl.pin("C3") == (1, "out") and ctl.pin("C4") == (0, "out")
    ctl.drive("C5", 1)
    status, out, err = orfa("gpio", "C")
    levels, modes = ctl.pin("C0")[0] | ctl.pin("C1")[0] << 1 | 0x28, 0x18
    assert out.splitlines()[1].split() == ["C", "0x%02X" % levels, "{:08b}".format(levels),
                                           "0x%02X" % modes, "{:08b}".format(modes)]
    assert orfa("gpio", "C", "0x10", "0x10") == (0, "", "")
    assert ctl.pin("C3") == (1, "out") and ctl.pin("C4") == (1, "out")
    assert orfa("gpio", "C", "0", "--input", "0x18") == (0, "", "")
    ctl.drive("C5", None)
    assert ctl.pin("C3") == (0, "in") and ctl.pin("C4") == (0, "in")
    status, out, err = orfa("gpio")
    assert [line.split()[0] for line in out.splitlines()] == ["port"] + list(M32D.gpio_ports)


def test_spi(orfa):
    assert orfa("spi", "bind", "0", "C", "2") == (0, "", "")
    assert orfa("spi", "config") == (0, "\n".join([
        "clock 921600 Hz (divider 2), mode 0, MSB first",
        "channel 0: chip select PC2", "channel 1: unbound", "channel 2: unbound",
        "channel 3: unbound", ""]), "")
    # the 25-series EEPROM: WREN, WRITE at 0x20, READ it back
    assert orfa("spi", "transfer", "0", "0x06") == (0, "0xff\n", "")
    assert orfa("spi", "transfer", "0", "0x02", "0x20", "0xAB", "0xCD") == (
        0, "0xff 0xff 0xff 0xff\n", "")
    assert orfa("spi", "transfer", "0", "0x03", "0x20", "0", "0") == (
        0, "0xff 0xff 0xab 0xcd\n", "")
    assert orfa("spi", "transfer", "1", "0x03") == (
        1, "", "orfa: 0xAA spi DATA: write refused: NOT_BOUND (SPI channel without a"
               " chip-select line)\n")
    assert orfa("spi", "config", "--div", "6", "--lsb") == (0, "", "")
    assert orfa("spi", "config")[1].splitlines()[0] == "clock 57600 Hz (divider 6), mode 0, LSB first"
    assert orfa("spi", "config", "--div", "2", "--msb") == (0, "", "")


def test_status(orfa):
    assert orfa("status") == (0, "\n".join([
        "board        0xAA",
        "status       00 OK: the last operation succeeded",
        "reset cause  power",
        "failsafe     off", ""]), "")
    status, out, err = orfa("status", "--clear-reset", "--failsafe", "250")
    assert out.splitlines()[2:] == ["reset cause  none since cleared", "failsafe     250 ms"]
    assert orfa("status", "--failsafe", "0")[1].splitlines()[-1] == "failsafe     off"
    status, out, err = orfa("--addr", "0x10", "status")
    assert out.splitlines()[0] == "board        0x10"
    assert orfa("status", "--failsafe", "20000")[0] == 2
