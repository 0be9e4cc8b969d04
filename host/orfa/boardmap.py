"""The board maps: what the host knows of each board, read from
orfa/maps/<board>.json.

Those files are generated from the C definitions the firmware is built from
(`make map`, tools/mapgen.c: boards/<board>/, the driver headers, the status
and error enums) and never edited by hand; tests/host/test_boardmap.py fails
when they drift from the C. Register numbers here are those of a build with
every driver of the board; a build that leaves drivers out moves the later
ones down, so clients of a live board take the start of each driver from its
introspection (orfa.board.Board) and only the offsets from here.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from typing import Dict, Iterable, Optional, Tuple

BOARDS: Tuple[str, ...] = ("m32d", "m128s")


@dataclass(frozen=True)
class Pin:
    """A pin with a fixed function: port letter, bit, function, index."""

    port: str
    bit: int
    function: str
    index: int

    @property
    def label(self) -> str:
        return "P%s%d" % (self.port, self.bit)

    @property
    def signal(self) -> str:
        """The simulator's name of the pin ("D5": its signals, `pin D5`)."""
        return "%s%d" % (self.port, self.bit)


@dataclass(frozen=True)
class DriverMap:
    """One driver of a board: introspection record and register names."""

    name: str
    uid: int
    major: int
    minor: int
    start: int
    count: int
    registers: Tuple[str, ...]

    @property
    def version(self) -> str:
        return "%d.%d" % (self.major, self.minor)

    def offset(self, register: str) -> int:
        """A register's offset inside the driver's range ("SP" -> 1)."""
        try:
            return self.registers.index(register.upper())
        except ValueError:
            raise KeyError("driver %s has no register %r (%s)"
                           % (self.name, register, ", ".join(self.registers))) from None


@dataclass(frozen=True)
class Code:
    """A status register value or a protocol error code, with its meaning."""

    code: int
    name: str
    text: str


@dataclass(frozen=True)
class BoardMap:
    """One board's map (fields as in the JSON file)."""

    board: str
    name: str
    mcu: str
    f_cpu: int
    avrdude_part: str
    fuses: Dict[str, int]
    uart: int
    local_address: int
    gpio_ports: str
    adc_port: str
    servo_channels: int
    limits: Dict[str, int]
    pins: Tuple[Pin, ...]
    drivers: Tuple[DriverMap, ...]
    reset_causes: Dict[str, int]

    def driver(self, name: str) -> DriverMap:
        for drv in self.drivers:
            if drv.name == name:
                return drv
        raise KeyError("%s has no driver %r (%s)"
                       % (self.name, name, ", ".join(d.name for d in self.drivers)))

    def has(self, name: str) -> bool:
        return any(d.name == name for d in self.drivers)

    def reg(self, driver: str, register: str) -> int:
        """The register number in a build with every driver: ("servo", "SP") -> 0x13."""
        drv = self.driver(driver)
        return drv.start + drv.offset(register)

    def driver_by_uid(self, uid: int) -> Optional[DriverMap]:
        for drv in self.drivers:
            if drv.uid == uid:
                return drv
        return None

    @property
    def uids(self) -> Tuple[int, ...]:
        return tuple(d.uid for d in self.drivers)

    def pins_of(self, function: str, index: Optional[int] = None) -> Tuple[Pin, ...]:
        """The pins of a function (and index: the channel, the motor)."""
        return tuple(p for p in self.pins if p.function == function
                     and (index is None or p.index == index))


@lru_cache(maxsize=None)
def _read(board: str) -> dict:
    if board not in BOARDS:
        raise ValueError("no board %r (%s)" % (board, ", ".join(BOARDS)))
    text = resources.files("orfa").joinpath("maps", board + ".json").read_text()
    return json.loads(text)


@lru_cache(maxsize=None)
def load(board: str) -> BoardMap:
    """The map of `board` ("m32d" or "m128s")."""
    raw = _read(board)
    return BoardMap(
        board=raw["board"], name=raw["name"], mcu=raw["mcu"], f_cpu=raw["f_cpu"],
        avrdude_part=raw["avrdude"]["part"], fuses=dict(raw["avrdude"]["fuses"]),
        uart=raw["uart"], local_address=raw["local_address"],
        gpio_ports=raw["gpio_ports"], adc_port=raw["adc_port"],
        servo_channels=raw["servo_channels"], limits=dict(raw["limits"]),
        pins=tuple(Pin(**p) for p in raw["pins"]),
        drivers=tuple(DriverMap(registers=tuple(d.pop("registers")), **d)
                      for d in (dict(d) for d in raw["drivers"])),
        reset_causes=dict(raw["reset_causes"]),
    )


def _codes(key: str) -> Dict[int, Code]:
    # The same in every board's map (one C enum): take the first board's.
    return {c["code"]: Code(**c) for c in _read(BOARDS[0])[key]}


def _shared(key: str):
    """A fact every board's map holds alike: its value (a ValueError names
    the boards if they differ)."""
    values = {board: _read(board)[key] for board in BOARDS}
    if any(v != values[BOARDS[0]] for v in values.values()):
        raise ValueError("the board maps differ in %r: %s" % (key, values))
    return values[BOARDS[0]]


#: The clock of every board in Hz (board.h's BOARD_CLOCK_HZ): one for all,
#: as the simulator steps its boards by one cycle count.
F_CPU: int = _shared("f_cpu")

#: The bus addresses a slave board or a part may be given, 8-bit form
#: (firmware/i2c_addr.h): even, ADDRESS_MIN..ADDRESS_MAX, which leaves out
#: the addresses I2C reserves.
ADDRESS_MIN: int = _shared("bus_address")["min"]
ADDRESS_MAX: int = _shared("bus_address")["max"]
#: The rule in words, for messages and help: "even, 0x10..0xEE".
ADDRESS_TEXT = "even, 0x%02X..0x%02X" % (ADDRESS_MIN, ADDRESS_MAX)


def address_ok(addr8: int) -> bool:
    """Whether addr8 is a bus address a slave board or a part may have."""
    return addr8 % 2 == 0 and ADDRESS_MIN <= addr8 <= ADDRESS_MAX


#: The functions a board may give a pin (firmware/board_fn.h), the names
#: of Pin.function.
PIN_FUNCTIONS: Tuple[str, ...] = tuple(_shared("pin_functions"))

#: The status register's values: code -> Code(code, name, text).
STATUS: Dict[int, Code] = _codes("status")
#: The protocol's error codes: code -> Code(code, name, text).
ERRORS: Dict[int, Code] = _codes("errors")


def by_uids(uids: Iterable[int]) -> Optional[BoardMap]:
    """The board whose drivers are exactly these UIDs (introspection order),
    or else the one whose UIDs contain them in order (a build with drivers
    left out); None if no board fits."""
    uids = tuple(uids)
    for board in BOARDS:
        if load(board).uids == uids:
            return load(board)
    for board in BOARDS:
        it = iter(load(board).uids)
        if uids and all(u in it for u in uids):
            return load(board)
    return None


@lru_cache(maxsize=None)
def _uid_index() -> Dict[int, Tuple[BoardMap, DriverMap]]:
    index: Dict[int, Tuple[BoardMap, DriverMap]] = {}
    for board in BOARDS:
        for drv in load(board).drivers:
            index.setdefault(drv.uid, (load(board), drv))
    return index


def by_uid(uid: int) -> Optional[Tuple[BoardMap, DriverMap]]:
    """The driver a UID names, with the first board that has it, or None.
    A UID names one driver on every board that has it (GPIO of 4 ports is
    0x0020, of 2 ports 0x0021), so its facts follow from the UID even on a
    build that left drivers out."""
    return _uid_index().get(uid)


#: Every UID a board can have -> the driver's name ("servo", "gpio", ...).
DRIVER_NAMES: Dict[int, str] = {uid: drv.name for uid, (_, drv) in _uid_index().items()}
