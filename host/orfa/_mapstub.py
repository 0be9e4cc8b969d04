"""Stand-in for orfa.boardmap until the generated map lands on main.

TEMPORARY: deleted when main's host/orfa/boardmap.py is merged; nothing
outside board.py/errors.py imports it.
"""

from typing import NamedTuple, Tuple

BOARDS = ("m32d", "m128s")


class Status(NamedTuple):
    code: int
    name: str
    text: str


STATUS = {s.code: s for s in (
    Status(0, "OK", "the last operation succeeded"),
    Status(1, "BAD_LENGTH", "the write had a length the register does not take"),
    Status(2, "BAD_VALUE", "a value out of range"),
    Status(3, "PIN_BUSY", "a pin the operation needs belongs to another function"),
    Status(4, "NOT_WRITABLE", "the register cannot be written"),
    Status(5, "NOT_READABLE", "the register cannot be read"),
    Status(6, "READ_WRAPPED", "introspection read past the last driver and went on with driver 1"),
    Status(7, "NOT_BOUND", "SPI channel without a chip-select line"),
    Status(8, "NO_REGISTER", "a write frame named a register that no driver maps"),
)}


class DriverMap(NamedTuple):
    name: str
    uid: int
    major: int
    minor: int
    start: int
    count: int
    registers: Tuple[str, ...]


class BoardMap(NamedTuple):
    board: str
    name: str
    gpio_ports: str
    adc_port: str
    servo_channels: int
    drivers: Tuple[DriverMap, ...]

    def driver(self, name):
        for d in self.drivers:
            if d.name == name:
                return d
        raise KeyError(name)

    def reg(self, driver, reg):
        d = self.driver(driver)
        return d.start + d.registers.index(reg)


def _drivers(spec):
    out, start = [], 0
    for name, uid, major, minor, regs in spec:
        out.append(DriverMap(name, uid, major, minor, start, len(regs), regs))
        start += len(regs)
    return tuple(out)


_INTRO = ("intro", 0x0000, 1, 0, ("INTRO", "STATUS"))
_SPI = ("spi", 0x0001, 1, 1, ("DATA", "CONFIG"))
_ADC = ("adc", 0x0040, 1, 1, ("RC", "RD"))
_SYS = ("sys", 0x0002, 1, 0, ("RESET", "FAILSAFE"))
_MAPS = {
    "m32d": BoardMap("m32d", "OR-AVR-M32-D", "ABCD", "A", 16, _drivers([
        _INTRO, ("gpio", 0x0020, 1, 1, tuple("VALUE_" + p for p in "ABCD")
                 + tuple("MODE_" + p for p in "ABCD")),
        _SPI, _ADC, ("motor", 0x0060, 1, 1, ("PWM1", "PWM2", "DIR1", "DIR2")),
        ("servo", 0x0031, 2, 0, ("RS", "SP")), _SYS])),
    "m128s": BoardMap("m128s", "OR-AVR-M128-S", "AF", "F", 32, _drivers([
        _INTRO, ("gpio", 0x0021, 1, 1, ("VALUE_A", "VALUE_F", "MODE_A", "MODE_F")),
        _SPI, _ADC, ("servo", 0x0030, 2, 0, ("RS", "SP")), _SYS])),
}


def load(board):
    return _MAPS[board]


def by_uids(uids):
    uids = list(uids)
    for m in _MAPS.values():
        if [d.uid for d in m.drivers] == uids:
            return m
    return None
