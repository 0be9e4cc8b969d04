"""A scripted gateway behind a pyserial-like object, for the Board and
Gateway.run tests without a simulator.

`FakeLine(answer)`: each request line the host writes is answered by
`answer(line)` (a reply text), when the host reads. It records every
request as sent, and the most request characters (terminators included)
that were ever unanswered: the flow rule (docs/protocol.md) wants that below 256. Noise:
`extra[k]` lines come before the reply to request k, `garble[k]` replaces it.
A CR ends a request as an LF does (the firmware's rule).

`ChattyLine`: a FakeLine whose far end also never stops talking (NMEA
sentences, an echo, random bytes, a board at another rate: `at_rate`).
"""

from __future__ import annotations

import itertools
import random
import re
import time
from collections import deque
from typing import Callable, Dict, Iterable, Iterator, List, Optional


class FakeLine:
    def __init__(self, answer: Callable[[str], Optional[str]]):
        self.answer = answer
        self.written: List[str] = []
        self.extra: Dict[int, List[bytes]] = {}
        self.garble: Dict[int, bytes] = {}
        self.timeout = 0.2
        self.baudrate = 115200
        self._partial = b""
        self._queue: deque = deque()
        self._out = bytearray()
        self._answered = 0
        self.in_flight = 0
        self.max_in_flight = 0
        self.is_open = True

    def forget(self) -> None:
        """Forget the requests sent so far: `written` empties and the next
        request is number 0 for `extra` and `garble`."""
        del self.written[:]
        self._answered = 0

    # --- the pyserial side the Gateway uses -------------------------------------
    def write(self, data: bytes) -> int:
        self._partial += bytes(data)
        while True:
            m = re.search(b"[\r\n]", self._partial)
            if m is None:
                break
            line, self._partial = self._partial[:m.start()], self._partial[m.end():]
            text = line.decode("ascii", "replace")
            self.written.append(text)
            self._queue.append(text)
            self.in_flight += len(line) + 1
            self.max_in_flight = max(self.max_in_flight, self.in_flight)
        return len(data)

    def flush(self) -> None:
        pass

    @property
    def in_waiting(self) -> int:
        return len(self._out)

    def read_until(self, expected: bytes = b"\n") -> bytes:
        if not self._out:
            self._produce()
        if not self._out:
            return b""                                  # the port's timeout
        end = self._out.find(b"\n")
        end = len(self._out) if end < 0 else end + 1
        chunk = bytes(self._out[:end])
        del self._out[:end]
        return chunk

    def close(self) -> None:
        self.is_open = False

    # --- the board side -----------------------------------------------------------
    def _produce(self) -> None:
        while self._queue:
            line = self._queue.popleft()
            self.in_flight -= len(line) + 1
            if not line.strip(" ") or line.lstrip(" ").startswith("#"):
                continue
            k = self._answered
            self._answered += 1
            for noise in self.extra.get(k, []):
                self._out += noise
            if k in self.garble:
                self._out += self.garble[k]
            else:
                reply = self.answer(line)
                if reply is None:
                    return                              # a board that stays silent
                self._out += reply.encode("ascii") + b"\r\n"
            return


def synced_gateway(monkeypatch, line: FakeLine, timeout: float = 0.2):
    """A Gateway whose port is `line` (pyserial's serial_for_url patched to
    give it, for any URL), its opening sync done and left out of
    line.written. The line's answers must include `V` and `C`."""
    from orfa.gateway import Gateway
    monkeypatch.setattr("orfa.gateway.serial.serial_for_url", lambda url, **kw: line)
    gw = Gateway("fake://", timeout=timeout)
    gw.in_step()
    line.forget()
    return gw


class ChattyLine(FakeLine):
    """A FakeLine whose far end, while `chatty`, never stops talking: each
    read first lets the board answer a waiting request, then adds the next
    chunk of `talk` (an endless iterator of bytes), `pace` seconds apart,
    as a line that carries more than replies does. echo=True: every byte
    the host writes comes back as well (an echoing modem). board=False: while
    the line talks, no ORFA board answers (a GPS on the wrong port)."""

    def __init__(self, answer: Callable[[str], Optional[str]], talk: Iterator[bytes],
                 chatty: bool = True, echo: bool = False, board: bool = True,
                 pace: float = 0.002):
        super().__init__(answer)
        self.talk = talk
        self.chatty = chatty
        self.echo = echo
        self.board = board
        self.pace = pace

    def write(self, data: bytes) -> int:
        if self.chatty and self.echo:
            self._out += bytes(data)
        return super().write(data)

    @property
    def in_waiting(self) -> int:
        return len(self._out) + (1 if self.chatty else 0)

    def read_until(self, expected: bytes = b"\n") -> bytes:
        if self.chatty:
            time.sleep(self.pace)
            if self.board and self._queue:
                self._produce()
            self._out += next(self.talk)
        return super().read_until(expected)


def at_rate(data: bytes, sent_baud: int, read_baud: int) -> bytes:
    """What a UART at read_baud takes from `data` sent 8N1, back to back,
    at sent_baud: it finds a start bit on the falling edge (16x
    oversampling), samples each bit in its middle and keeps a byte with a
    framing error as it is (Linux without PARMRK)."""
    bits: List[int] = [1] * 4
    for b in data:
        bits += [0] + [(b >> i) & 1 for i in range(8)] + [1]
    bits += [1] * 12

    def level(t: float) -> int:
        return bits[min(int(t * sent_baud), len(bits) - 1)]
    end = len(bits) / sent_baud
    step = 1.0 / read_baud
    out = bytearray()
    t = 0.0
    while t < end:
        if level(t):
            t += step / 16
            continue
        mid = t + step / 2
        if level(mid):                      # a glitch, not a start bit
            t += step / 16
            continue
        out.append(sum(level(mid + (i + 1) * step) << i for i in range(8)))
        t = mid + 9 * step                  # the stop bit; low: a framing error
        while t < end and not level(t):
            t += step / 16
    return bytes(out)


def endless(chunks: Iterable[bytes]) -> Iterator[bytes]:
    return itertools.cycle(list(chunks))


NMEA = [b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n",
        b"$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n",
        b"$GPGSV,2,1,08,01,40,083,46,02,17,308,41,12,07,344,39,14,22,228,45*75\r\n"]


def random_bytes(seed: int = 16, size: int = 64) -> Iterator[bytes]:
    rng = random.Random(seed)
    while True:
        yield bytes(rng.randrange(256) for _ in range(size))


#: A line's contents that are not replies, each (an endless talk for
#: ChattyLine, echo, board): a GPS on the wrong port, the same with a board
#: that answers too, an echoing modem that also reports calls, random bytes
#: on a board's line, ORFA boards at 9600 and at 460800 read at 115200.
TALKS = {
    "nmea": (lambda: endless(NMEA), False, False),
    "nmea+board": (lambda: endless(NMEA), False, True),
    "echo": (lambda: endless([b"", b"", b"\r\nRING\r\n"]), True, False),
    "random": (lambda: random_bytes(), False, True),
    "9600": (lambda: endless([at_rate(b"V1.1\r\nSWAAP\r\nC0063\r\n", 9600, 115200)]),
             False, False),
    "460800": (lambda: endless([at_rate(b"SR0102030405P\r\nV1.1\r\n" * 4, 460800, 115200)]),
               False, False),
}
