"""The English texts of the generated board pages (docs/board-<board>.md),
shaped like tools/docgen_ru.py's and keyed by the same names of the board
map. The status and error codes' English texts are the map's own.
"""

from orfa import boardmap
from orfa.boards import DRIVER_TITLES as DRIVERS  # noqa: F401 (a table of the set)

LANGUAGE = "English"


def __getattr__(name):
    """STATUS and ERRORS: the map's texts by name, read when asked (PEP 562),
    so they are never a copy of boardmap's."""
    if name not in ("STATUS", "ERRORS"):
        raise AttributeError(name)
    return {c.name: c.text for c in getattr(boardmap, name).values()}


#: One line per register, by (driver, register); GPIO's VALUE_x / MODE_x
#: share the text of VALUE / MODE (docs/registers.md has the rest).
REGISTERS = {
    ("intro", "INTRO"): "write N, read records from driver N (0: the count)",
    ("intro", "STATUS"): "result of the last register access (read only)",
    ("gpio", "VALUE"): "levels (read), output level or pull-up (write [value][mask])",
    ("gpio", "MODE"): "directions, 1 = output (write [modes][mask])",
    ("spi", "DATA"): "write [channel][bytes]: an exchange; read: bytes received",
    ("spi", "CONFIG"): "[channel][port][line] chip select; [FF][x][settings] the bus",
    ("adc", "RC"): "[settings][channel mask]",
    ("adc", "RD"): "results, 1 or 2 bytes per channel (read only)",
    ("motor", "PWM1"): "motor 1 duty 0-255",
    ("motor", "PWM2"): "motor 2 duty 0-255",
    ("motor", "DIR1"): "motor 1 direction, 0 forward, 1 backward",
    ("motor", "DIR2"): "motor 2 direction",
    ("servo", "RS"): "mask of pulsing channels (read; writes change nothing)",
    ("servo", "SP"): "[channel][width hi][width lo] x 1-16, us, 0 = off",
    ("sys", "RESET"): "reset causes since the last clear; write a mask to clear",
    ("sys", "FAILSAFE"): "link-loss failsafe, ms big-endian, 0 = off",
}

#: Pin functions of the map, for the legend under the pin table.
PIN_FUNCTIONS = {
    "UART_RX": "RXD: serial port receive (from the PC)",
    "UART_TX": "TXD: serial port transmit (to the PC)",
    "TWI_SCL": "SCL: I2C bus clock",
    "TWI_SDA": "SDA: I2C bus data",
    "SPI_SS": "SS: an output held high so that SPI stays master",
    "SPI_MOSI": "MOSI: SPI data to the device",
    "SPI_MISO": "MISO: SPI data from the device",
    "SPI_SCK": "SCK: SPI clock",
    "MOTOR_PWM": "PWMn: motor n's PWM",
    "MOTOR_DIR": "DIRn: motor n's direction",
    "SERVO": "Sn: servo channel n",
    "SERVO_CLK": "CLKn: clock input of CD4017 counter n",
    "SERVO_RST": "RST: common reset of the CD4017 counters",
}

#: Reset causes of the sys driver's RESET register, by name.
RESET_CAUSES = {
    "power": "power-on (PORF)",
    "external": "the RESET pin (EXTRF)",
    "brownout": "brown-out (BORF)",
    "watchdog": "watchdog (WDRF)",
    "jtag": "JTAG (JTRF)",
}

#: Headings, column names and the fixed sentences of the page.
TEXT = {
    "title": "# %s (%s, `BOARD=%s`)\n",
    "intro": ("Clock %.4f MHz; serial port USART%d; the gateway's own address "
              "`%02X` (7-bit 0x%02X); avrdude part `%s`, fuses %s.\n"),
    "drivers": "## Drivers (introspection order)\n",
    "drivers_head": "| # | UID | driver | version | registers |",
    "gpio_ports": "ports %s",
    "registers": "## Register map\n",
    "registers_head": "| register | driver | name | what |",
    "limits": ("Limits: requests %d characters, replies %d; servo widths %d-%d us, "
               "%d triples per write, %s; SPI %s, %s per exchange; "
               "FAILSAFE up to %d ms.\n"),
    "pins": "## Pins\n",
    "pins_head": "| port | 7 | 6 | 5 | 4 | 3 | 2 | 1 | 0 |",
    "pins_note": ("IO = a GPIO line (ports %s), when no other function holds it; "
                  "ADn = ADC channel n%s. The other labels:\n"),
    "pins_note_4017": " (here the servo channels go through CD4017 counters)",
    "status": "## Status register values\n",
    "status_head": "| code | name | meaning |",
    "errors": "## Protocol error codes\n",
    "errors_head": "| reply | name | meaning |",
    "resets": "## Reset causes (the sys driver's RESET register)\n",
    "resets_head": "| bit | name | cause |",
    "see": ("More on each register: [registers.md](registers.md), "
            "[protocol.md](protocol.md). По-русски: "
            "[ru/board-%s.md](ru/board-%s.md).\n"),
}


def channels(n: int) -> str:
    return "%d channel%s" % (n, "" if n == 1 else "s")


def nbytes(n: int) -> str:
    return "%d byte%s" % (n, "" if n == 1 else "s")
