"""board.spi: the SPI driver's CONFIG (chip selects, bus) and DATA (exchanges)."""

from __future__ import annotations

from typing import Dict

from ..protocol import LimitError

#: CONFIG's first byte that sets the bus instead of a channel
BUS = 0xFF


class Spi:
    def __init__(self, board):
        self.board = board
        limits = board.board_map("spi").limits
        #: chip-select channels, and the most bytes of one exchange (the
        #: driver's; a request through the gateway holds fewer, see transfer)
        self.channels: int = limits["spi_channels"]
        self.max_bytes: int = limits["spi_bytes"]

    def _ports(self) -> str:
        return self.board.board_map("gpio").gpio_ports

    def bind(self, channel: int, port: str, line: int) -> None:
        """Line `line` of GPIO port `port` ("B") as channel's chip select."""
        ports = self._ports()
        if not isinstance(channel, int) or not 0 <= channel < self.channels:
            raise ValueError("SPI channel %r: channels are 0..%d" % (channel, self.channels - 1))
        if not isinstance(port, str) or len(port) != 1 or port.upper() not in ports:
            raise ValueError("no GPIO port %r on this board (ports %s)" % (port, ", ".join(ports)))
        if not isinstance(line, int) or not 0 <= line <= 7:
            raise ValueError("line must be 0..7, not %r" % (line,))
        self.board.write("spi", "CONFIG", [channel, ports.index(port.upper()), line])

    def configure(self, clock_div: int = 2, mode: int = 0, lsb_first: bool = False) -> None:
        """The bus: SCK = F_CPU / 2^(clock_div+1) (0..6), SPI mode 0..3, bit order."""
        if not isinstance(clock_div, int) or not 0 <= clock_div <= 6:
            raise ValueError("clock_div must be 0..6, not %r" % (clock_div,))
        if not isinstance(mode, int) or not 0 <= mode <= 3:
            raise ValueError("SPI mode must be 0..3, not %r" % (mode,))
        settings = clock_div | mode << 3 | (0x20 if lsb_first else 0)
        self.board.write("spi", "CONFIG", [BUS, 0, settings])

    def config(self) -> Dict[str, object]:
        """{"clock_div", "mode", "lsb_first", "channels": {ch: (port, line) or None}}."""
        data = self.board.read("spi", "CONFIG", 1 + 2 * self.channels)
        ports = self._ports()
        chans = {}
        for ch in range(self.channels):
            port, line = data[1 + 2 * ch], data[2 + 2 * ch]
            chans[ch] = None if port == 0xFF else (ports[port], line)
        s = data[0]
        return {"clock_div": s & 0x07, "mode": s >> 3 & 0x03, "lsb_first": bool(s & 0x20),
                "channels": chans}

    def transfer(self, channel: int, data: bytes) -> bytes:
        """Exchange data with the device on channel: a DATA write, then a
        DATA read of what came back, two requests pipelined. The 128
        characters of a request hold 60 bytes to the gateway itself, 55
        to a slave (with its status read)."""
        data = bytes(data)
        if not isinstance(channel, int) or not 0 <= channel < self.channels:
            raise ValueError("SPI channel %r: channels are 0..%d" % (channel, self.channels - 1))
        if not 1 <= len(data) <= self.max_bytes:
            raise ValueError("an SPI transfer has 1..%d bytes, not %d" % (self.max_bytes, len(data)))
        b = self.board
        write = [b.op_write("spi", "DATA", bytes([channel]) + data)]
        read = [b.op_read("spi", "DATA", len(data))]
        try:
            results = b.execute([write, read])
        except LimitError as e:
            raise LimitError("SPI transfer of %d bytes does not fit a request: %s"
                             % (len(data), e)) from None
        return results[1][0]
