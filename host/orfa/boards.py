"""What the host knows of each board (SPEC section 1)."""

#: Driver UIDs each board can have, in register order. Builds may leave
#: drivers out (`make DRIVERS=...`); introspection then lists fewer.
BOARD_UIDS = {
    "m32d": (0x0000, 0x0020, 0x0001, 0x0040, 0x0060, 0x0031, 0x0002),
    "m128s": (0x0000, 0x0021, 0x0001, 0x0040, 0x0030, 0x0002),
}

#: The sys driver: reset causes and the link-loss failsafe.
SYS_UID = 0x0002

#: The sys driver's registers (UID 0x0002, always built in and last, so
#: they follow every other driver's; docs/registers.md "sys"): RESET and
#: FAILSAFE of each board with all its drivers. A build that leaves drivers
#: out moves them down: ask introspection then (Gateway.sys_register).
SYS_REGISTER = {"m32d": 0x14, "m128s": 0x0C}

#: RESET's bits (the MCU's MCUCSR layout), by cause name.
RESET_CAUSES = {"power": 0x01, "external": 0x02, "brownout": 0x04,
                "watchdog": 0x08, "jtag": 0x10}
RESET_CAUSES_ALL = 0x1F

#: FAILSAFE's longest timeout in milliseconds (0 = off).
FAILSAFE_MAX_MS = 18000


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

DRIVER_NAMES = {
    0x0000: "introspection",
    0x0001: "SPI",
    0x0002: "system (reset cause, failsafe)",
    0x0020: "GPIO (4 ports)",
    0x0021: "GPIO (2 ports)",
    0x0030: "servos (32)",
    0x0031: "servos (16)",
    0x0040: "ADC",
    0x0060: "motors",
}
