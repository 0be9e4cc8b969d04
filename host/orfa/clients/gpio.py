"""board.gpio: the GPIO driver's value and mode registers, by port letter."""

from __future__ import annotations


class Gpio:
    def __init__(self, board):
        self.board = board
        #: the board's GPIO ports in register order: "ABCD", "AF"
        self.ports: str = board.board_map("gpio").gpio_ports

    def _port(self, port: str) -> str:
        if not isinstance(port, str) or port.upper() not in self.ports or len(port) != 1:
            raise ValueError("no GPIO port %r on this board (ports %s)"
                             % (port, ", ".join(self.ports)))
        return port.upper()

    @staticmethod
    def _byte(name: str, value: int) -> int:
        if not isinstance(value, int) or isinstance(value, bool) or not 0 <= value <= 0xFF:
            raise ValueError("%s must be 0..255, not %r" % (name, value))
        return value

    def _data(self, value: int, mask: int) -> bytes:
        value, mask = self._byte("value", value), self._byte("mask", mask)
        return bytes([value]) if mask == 0xFF else bytes([value, mask])

    def read(self, port: str) -> int:
        """The port's pin levels (PINx)."""
        return self.board.read("gpio", "VALUE_" + self._port(port), 1)[0]

    def write(self, port: str, value: int, mask: int = 0xFF) -> None:
        """PORTx of the lines in mask: output levels, pull-ups on inputs.
        Lines of other functions are skipped by the board."""
        self.board.write("gpio", "VALUE_" + self._port(port), self._data(value, mask))

    def modes(self, port: str) -> int:
        """The port's directions (DDRx, 1 = output)."""
        return self.board.read("gpio", "MODE_" + self._port(port), 1)[0]

    def set_modes(self, port: str, modes: int, mask: int = 0xFF) -> None:
        """Directions of the lines in mask (1 = output)."""
        self.board.write("gpio", "MODE_" + self._port(port), self._data(modes, mask))
