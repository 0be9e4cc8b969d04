"""What the host knows of each board (SPEC section 1)."""

#: Driver UIDs each board can have, in register order. Builds may leave
#: drivers out (`make DRIVERS=...`); introspection then lists fewer.
BOARD_UIDS = {
    "m32d": (0x0000, 0x0020, 0x0001, 0x0040, 0x0060, 0x0031),
    "m128s": (0x0000, 0x0021, 0x0001, 0x0040, 0x0030),
}

DRIVER_NAMES = {
    0x0000: "introspection",
    0x0001: "SPI",
    0x0020: "GPIO (4 ports)",
    0x0021: "GPIO (2 ports)",
    0x0030: "servos (32)",
    0x0031: "servos (16)",
    0x0040: "ADC",
    0x0060: "motors",
}
