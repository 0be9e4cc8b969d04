"""A scripted gateway behind a pyserial-like object, for the Board and
Gateway.run tests without a simulator.

`FakeLine(answer)`: each request line the host writes is answered by
`answer(line)` (a reply text), when the host reads. It records every
request as sent, and the most request characters (terminators included)
that were ever unanswered: the flow rule (docs/protocol.md) wants that below 256. Noise:
`extra[k]` lines come before the reply to request k, `garble[k]` replaces it.
"""

from __future__ import annotations

from collections import deque
from typing import Callable, Dict, List, Optional


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

    # --- the pyserial side the Gateway uses -------------------------------------
    def write(self, data: bytes) -> int:
        self._partial += bytes(data)
        while b"\n" in self._partial:
            line, _, self._partial = self._partial.partition(b"\n")
            text = line.decode("ascii")
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
