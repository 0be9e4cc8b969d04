"""What the host knows of each board (docs/boards.md), from the board maps
(orfa.boardmap: generated from the firmware's C definitions)."""

from . import boardmap

#: Driver UIDs each board can have, in register order. Builds may leave
#: drivers out (`make DRIVERS=...`); introspection then lists fewer.
BOARD_UIDS = {board: boardmap.load(board).uids for board in boardmap.BOARDS}

#: The sys driver: reset causes and the link-loss failsafe.
SYS_UID = boardmap.load("m32d").driver("sys").uid

#: The sys driver's RESET register (FAILSAFE follows it) of each board with
#: all its drivers (UID 0x0002, always built in and last; docs/registers.md
#: "sys"). A build that leaves drivers out moves it down: ask introspection
#: then (Board.register("sys", "RESET")).
SYS_REGISTER = {board: boardmap.load(board).reg("sys", "RESET") for board in boardmap.BOARDS}

#: RESET's bits (the MCU's MCUCSR layout), by cause name.
RESET_CAUSES = dict(boardmap.load("m32d").reset_causes)
RESET_CAUSES_ALL = sum(RESET_CAUSES.values())

#: FAILSAFE's longest timeout in milliseconds (0 = off).
FAILSAFE_MAX_MS = boardmap.load("m32d").limits["failsafe_max_ms"]


def reset_causes(byte: int) -> frozenset:
    """RESET's byte as cause names: 0x09 -> {"power", "watchdog"}."""
    return frozenset(name for name, bit in RESET_CAUSES.items() if byte & bit)


def reset_cause_bits(causes) -> int:
    """Cause names as RESET's bits (for a clear); unknown names: ValueError."""
    bits = 0
    for name in causes:
        if name not in RESET_CAUSES:
            raise ValueError("no reset cause %r (%s)" % (name, ", ".join(RESET_CAUSES)))
        bits |= RESET_CAUSES[name]
    return bits


#: What each driver is, for people (the generated docs' driver tables).
DRIVER_TITLES = {
    "intro": "introspection",
    "spi": "SPI",
    "sys": "system (reset cause, failsafe)",
    "gpio": "GPIO",
    "servo": "servos",
    "adc": "ADC",
    "motor": "motors",
}


def driver_title(uid: int) -> str:
    """A driver's title by UID: "servos (16)", "GPIO (4 ports)", ..."""
    hit = boardmap.by_uid(uid)
    if hit is None:
        return "unknown"
    m, drv = hit
    if drv.name == "servo":
        return "servos (%d)" % m.servo_channels
    if drv.name == "gpio":
        return "GPIO (%d ports)" % len(m.gpio_ports)
    return DRIVER_TITLES.get(drv.name, drv.name)


DRIVER_NAMES = {uid: driver_title(uid) for uid in boardmap.DRIVER_NAMES}
