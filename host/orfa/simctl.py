"""Client of orfa-sim's control socket (--control PATH; docs/simulator.md).

One request line, one reply line; a reply starting with ``ERR`` raises
SimControlError. The board keeps running between requests.
"""

from __future__ import annotations

import socket
import time
from typing import Dict, List, Optional, Tuple, Union

from .closing import Closing
from .errors import SimControlError

#: Bytes one `rx` request carries at most here: its hex fits a request line
#: (1023 characters) with any cycle.
RX_MAX = 480


def parse_edges(reply: str) -> List[Tuple[int, int]]:
    """An `edges` reply ("cycle:level ..." or "-") as [(cycle, level), ...]."""
    if reply == "-":
        return []
    return [(int(c), int(lv)) for c, lv in (item.split(":") for item in reply.split())]


class SimControl(Closing):
    def __init__(self, path: str, timeout: float = 60.0, connect_timeout: float = 10.0):
        self.path = str(path)
        self.timeout = timeout
        deadline = time.monotonic() + connect_timeout
        while True:
            try:
                self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
                self.sock.connect(self.path)
                break
            except OSError:
                self.sock.close()
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.02)
        self.sock.settimeout(timeout)
        self._buf = b""

    def close(self) -> None:
        self.sock.close()

    def request(self, line: str) -> str:
        """Send one request, return its reply line (without newline)."""
        return self.requests([line])[0]

    def requests(self, lines: List[str]) -> List[str]:
        """Send several requests at once and return their replies. The
        simulator answers them in order, each as soon as the one before it
        is answered: a `wait` followed by another request has that request
        act at the wait's cycle."""
        self.sock.sendall("".join(line + "\n" for line in lines).encode())
        replies = []
        for _ in lines:
            while b"\n" not in self._buf:
                chunk = self.sock.recv(65536)
                if not chunk:
                    raise SimControlError("orfa-sim closed the control socket")
                self._buf += chunk
            reply, self._buf = self._buf.split(b"\n", 1)
            replies.append(reply.decode())
        bad = [r for r in replies if r.startswith("ERR")]
        if bad:
            raise SimControlError(bad[0])
        return replies

    # --- commands -------------------------------------------------------------
    def time(self) -> int:
        return int(self.request("time"))

    def wait(self, cycles: int) -> int:
        """Returns the cycle at which the wait ended (>= now + cycles)."""
        return int(self.request("wait %d" % cycles))

    def wait_i2c(self, count: int, within: int) -> int:
        """Let simulated time pass until the bus's master has clocked `count`
        more bytes (the trace's `twi addr|write|read`); the cycle the wait
        ended at, at most a quantum (4 cycles) and an instruction after the
        last byte's end. SimControlError when `within` cycles pass first. In
        a batch (requests), "wait i2c N WITHIN" has the requests behind it
        act at that byte."""
        return int(self.request("wait i2c %d %d" % (count, within)))

    # --- which board ----------------------------------------------------------
    #: A slave board's view (SimControl.slave) prefixes names with "10/" and
    #: puts "@10" first in requests that name no signal; names that already
    #: carry a prefix ("12/A5") are left alone, so any view reaches any board.
    _prefix = ""
    _at = ""

    def _name(self, name: str) -> str:
        return name if "/" in name else self._prefix + name

    def _board(self, request: str) -> str:
        if not self._at:
            return request
        cmd, _, rest = request.partition(" ")
        return ("%s %s %s" % (cmd, self._at, rest)).rstrip()

    def slave(self, addr: int) -> "SimControl":
        """The same socket, aimed at the slave board with 8-bit address `addr`."""
        return _SlaveView(self, addr)

    def pin(self, name: str) -> Tuple[int, str]:
        """(level, "out" | "in" | "in pullup" | "in ext" | "out oc" | "out spi" |
        "in spi" (MISO, driven by the SPI bus) | "out uart")."""
        level, how = self.request("pin %s" % self._name(name)).split(" ", 1)
        return int(level), how

    def drive(self, name: str, value: Union[int, str, None]) -> None:
        """Drive pin NAME to 0 or 1; None or "z" releases it."""
        v = "z" if value is None or value == "z" else str(int(value))
        self.request("drive %s %s" % (self._name(name), v))

    def adc(self, ch: Union[int, str], mv: int) -> None:
        self.request("adc %s %d" % (self._name(str(ch)), mv))

    def avcc(self, mv: int) -> None:
        self.request(self._board("avcc %d" % mv))

    def aref(self, mv: int) -> None:
        self.request(self._board("aref %d" % mv))

    def level(self, sig: str) -> int:
        return int(self.request("level %s" % self._name(sig)))

    def edges(self, sig: str, since: Optional[int] = None) -> List[Tuple[int, int]]:
        """[(cycle, level), ...], oldest first."""
        sig = self._name(sig)
        return parse_edges(self.request("edges %s" % sig if since is None
                                        else "edges %s %d" % (sig, since)))

    def window(self, sigs: List[str], cycles: int, during: List[str] = ()
               ) -> Tuple[int, int, Dict[str, List[Tuple[int, int]]]]:
        """Let `cycles` pass and take the edges of `sigs` in that window:
        (start, end, {sig: [(cycle, level), ...]}), every edge at or after
        start and before end. One batch (`time`, the requests `during`, e.g.
        `rx +N ...`, at the window's start, `wait`, an `edges` per signal
        answered at the wait's cycle), so the window is fixed in simulated
        time however the wall clock goes; `cycles` should stay within the
        1024 edges a signal keeps."""
        during = list(during)
        replies = self.requests(["time"] + during + ["wait %d" % cycles] +
                                ["edges %s" % self._name(s) for s in sigs])
        start, end = int(replies[0]), int(replies[1 + len(during)])
        return start, end, {s: [e for e in parse_edges(r) if start <= e[0] < end]
                            for s, r in zip(sigs, replies[2 + len(during):])}

    def measure(self, sig: str, n: Optional[int] = None, since: Optional[int] = None) -> Dict:
        """{"steady": 0|1} or {"high": (min, max, mean), "period": (...), "duty": f, "n": k}."""
        req = "measure %s" % self._name(sig)
        if n is not None or since is not None:
            req += " %d" % (n if n is not None else 50)
        if since is not None:
            req += " %d" % since
        words = self.request(req).split()
        if words[0] == "steady":
            return {"steady": int(words[1])}
        return {
            "high": (int(words[1]), int(words[2]), float(words[3])),
            "period": (int(words[5]), int(words[6]), float(words[7])),
            "duty": float(words[9]),
            "n": int(words[11]),
        }

    def spi(self) -> List[Dict]:
        """Exchanges since the last call: [{"cs": "C2", "mosi": bytes, "miso": bytes}]."""
        reply = self.request(self._board("spi"))
        if reply == "-":
            return []
        out = []
        for item in reply.split():
            cs, mosi, miso = item.split(":")
            out.append({"cs": cs, "mosi": bytes.fromhex(mosi), "miso": bytes.fromhex(miso)})
        return out

    def spidev(self, pin: str) -> str:
        return self.request("spidev %s" % self._name(pin))

    def signals(self) -> List[str]:
        """Every board's signals (a slave's as "10/servo3"); a slave view: its own."""
        return self.request(self._board("signals")).split()

    def stack(self, heap_start: int = 0) -> Dict[str, int]:
        """Peak stack use since the last reset (the simulator paints SRAM).

        heap_start: the end of the firmware's static data (avr-nm's
        __heap_start, minus 0x800000); 0 lets the simulator guess."""
        words = self.request(self._board("stack %d" % heap_start)).split()
        return {"peak": int(words[1]), "deepest": int(words[3], 16), "ramend": int(words[5], 16)}

    def rx(self, cycle: int, data: bytes) -> int:
        """Put `data` on the board's serial receive line, the first start bit
        at simulated `cycle`, back to back at the byte time the firmware set
        (640 cycles at 115200 baud). Returns the cycle the last byte's stop
        bit ends (it reaches the receiver then). At most 480 bytes a call
        (the request line's length); see docs/simulator.md."""
        if not 1 <= len(data) <= RX_MAX:
            raise ValueError("rx takes 1..%d bytes, not %d" % (RX_MAX, len(data)))
        return int(self.request("rx %d %s" % (cycle, bytes(data).hex().upper())))

    def rx_after(self, cycles: int, data: bytes) -> int:
        """As rx, the first start bit `cycles` after the cycle the simulator
        answers at (`rx +N`): never past, however late the request arrives."""
        if not 1 <= len(data) <= RX_MAX:
            raise ValueError("rx takes 1..%d bytes, not %d" % (RX_MAX, len(data)))
        return int(self.request("rx +%d %s" % (cycles, bytes(data).hex().upper())))

    def rx_stream(self, cycle: int, line: bytes, until: int, slip: int) -> Tuple[int, int]:
        """`line` (a request and its terminator) again and again on the serial
        line, back to back, from `cycle` (or `slip` cycles after now, should
        the simulation have passed it while it was asked: a loaded machine)
        until `until` (0: once); returns (the first start bit's cycle, the
        last stop bit's end)."""
        per = RX_MAX // len(line) if until else 1
        while True:
            try:
                end = self.rx(cycle, line * per)
                break
            except SimControlError as e:
                if "is past" not in str(e):
                    raise
                cycle = self.time() + slip
        first, at = cycle, end
        while at < until:
            end = self.rx(at, line * per)
            at = end
        return first, end

    def fault_hang(self) -> int:
        """The board stops running its program (interrupts off, the PC on an
        endless loop) until its watchdog resets it; returns the cycle."""
        return int(self.request(self._board("fault hang")))

    def reset(self, cause: str = "external") -> int:
        """Reset the board now: "external" (the RESET pin), "power" (a
        power cycle: SRAM lost) or "brownout"; returns the cycle."""
        return int(self.request(self._board("reset %s" % cause)))

    def line(self) -> Dict[str, int]:
        """The gateway's serial line: `pc` the PC's rate (its port's termios),
        `bit` its bit time and `board` the board's (UBRR/U2X), in cycles;
        `ubrr`, `rxen`, `since` (the cycle RXEN last went on), `fe` (frames
        with FE the firmware took from UDR), `pty` (bytes the simulator has
        taken from the PC's port), `dor` (frames the
        receiver lost to overrun: the firmware fell behind)."""
        words = self.request(self._board("line")).split()
        return {k: int(v) for k, v in zip(words[::2], words[1::2])}

    def wait_taken(self, total: int, step: int = 1000, timeout: float = 30.0) -> int:
        """Let simulated time pass, `step` cycles at a time, until the
        simulator has taken `total` bytes from the PC's port (`line`'s pty):
        a write to the port reaches it when the kernel gets to it, in wall
        time. The cycle reached; SimControlError if the bytes never come."""
        deadline = time.monotonic() + timeout
        while True:
            taken, now = self.requests(["line", "time"])
            words = taken.split()
            if int(words[words.index("pty") + 1]) >= total:
                return int(now)
            if time.monotonic() > deadline:
                raise SimControlError("the simulator took %s of %d bytes from the port"
                                      % (words[words.index("pty") + 1], total))
            self.wait(step)

    def peek(self, addr: int, n: int = 1) -> bytes:
        """n bytes of the MCU's data space from `addr` (SRAM, registers)."""
        return bytes.fromhex(self.request(self._board("peek %d %d" % (addr, n))))

    def isr(self, clear: bool = False) -> Dict[str, int]:
        """The board's TWI interrupt since the last clear: {"longest", "count",
        "total"} in cycles, from the vector's entry to its RETI; clear=True
        starts the counts again (after reading them)."""
        w = self.request(self._board("isr clear" if clear else "isr")).split()
        return {"longest": int(w[2]), "count": int(w[4]), "total": int(w[6])}

    def profile_on(self) -> None:
        """Count the board's cycles at each flash word from now (every
        count zero again); see profile()."""
        self.request(self._board("profile on"))

    def profile_off(self) -> None:
        """Stop counting; the counts stay for profile()."""
        self.request(self._board("profile off"))

    def profile(self) -> Dict[int, int]:
        """{byte address: cycles} since profile_on(), words never run left
        out. Every cycle between two instructions counts to the first: its
        own, an interrupt's entry after it, its sleep (docs/simulator.md)."""
        w = self.request(self._board("profile")).split()
        return {int(a, 16): int(c) for a, _, c in (x.partition(":") for x in w[1:])}

    def flag(self, vector: int, clear: bool = False) -> Dict[str, int]:
        """How long the board's interrupt flag of `vector` (its number in
        the vector table: the M32-D's Timer2 overflow is 5) stayed raised
        before its handler took it or the firmware cleared it, since the
        first call (which starts the watch) or the last clear: {"longest"
        in cycles, "count"}. Longer than the event's period (a Timer2
        wrap: 2048 cycles): an event was lost."""
        w = self.request(self._board("flag %d%s" % (vector, " clear" if clear else ""))).split()
        return {"longest": int(w[1]), "count": int(w[3])}

    def i2c_stuck(self, pulses: int) -> None:
        """A device on the I2C bus holds SDA low until it has seen `pulses`
        more SCL pulses (falling edges), as a slave does whose byte a master
        abandoned; 0 lets SDA go."""
        self.request("i2c stuck %d" % pulses)

    def i2c_hold_scl(self, on: bool) -> None:
        """A device on the I2C bus holds SCL low (on) or lets it go."""
        self.request("i2c hold-scl %s" % ("on" if on else "off"))

    def i2c_arb(self, byte: int, bit: int) -> None:
        """A device pulls SDA low for bit `bit` (0..7 MSB first, 8 the
        acknowledge) of byte `byte` (0: the address after the next START;
        every address and data byte after it counts) of the next
        transaction: where the master sends a 1 it loses arbitration
        (0x38). Fires once."""
        self.request("i2c arb %d %d" % (byte, bit))

    def i2c_glitch(self, cond: str, byte: int, bit: int) -> None:
        """A START (`cond` "start") or STOP ("stop") condition in bit `bit`
        (1..8) of byte `byte` of the next transaction, as i2c_arb counts
        them: a bus error (0x00) for the master and the addressed slave.
        Fires once."""
        self.request("i2c glitch %s %d %d" % (cond, byte, bit))

    def i2c_disarm(self) -> None:
        """Forget an i2c_arb or i2c_glitch that has not fired."""
        self.request("i2c disarm")

    def i2c_armed(self) -> str:
        """The fault armed for the next transaction: "arb BYTE BIT",
        "glitch start|stop BYTE BIT", or "none" once it fired."""
        w = self.request("i2c").split()
        return " ".join(w[w.index("fault") + 1:])

    def i2c(self) -> Dict[str, int]:
        """The bus lines: {"sda", "scl" (levels), "stuck" (pulses the stuck
        device still waits for), "hold_scl" (0/1)}."""
        w = self.request("i2c").split()
        return {"sda": int(w[1]), "scl": int(w[3]), "stuck": int(w[5]),
                "hold_scl": int(w[7] == "on")}

    def sense(self, addr: int, quantity: str, *values: float) -> None:
        """What the part at 8-bit bus address `addr` senses: `quantity`
        ("accel" X Y Z in m/s^2, "gyro" X Y Z in degrees/s, "field" X Y Z in
        microtesla, "temp" T in degrees C, "pressure" P in Pa, an SRF08's
        "range" MM [MM2] and "light" N), in physical units; the part reports
        it in its registers as its datasheet says. SimControlError for a
        quantity the part does not sense or a value outside its range."""
        self.request("sense @%02X %s %s" % (addr, quantity,
                                            " ".join(repr(float(v)) for v in values)))

    def srf08_range(self, addr: int, mm: int, mm2: Optional[int] = None) -> None:
        """What the SRF08 at 8-bit address `addr` sees at its next ping: a
        target `mm` millimetres away (0: none), optionally a second one."""
        self.request("srf08 %02X range %d" % (addr, mm) +
                     ("" if mm2 is None else " %d" % mm2))

    def srf08_light(self, addr: int, level: int) -> None:
        """The light level (0..255) its sensor reads at the next ping."""
        self.request("srf08 %02X light %d" % (addr, level))

    def srf08(self, addr: int) -> Dict[str, object]:
        """Its state: {"addr", "range": (mm, mm2), "light", "gain",
        "rangereg", "busy", "rangings"}."""
        w = self.request("srf08 %02X" % addr).split()
        return {"addr": int(w[1], 16), "range": (int(w[3]), int(w[4])),
                "light": int(w[6]), "gain": int(w[8]), "rangereg": int(w[10]),
                "busy": int(w[12]), "rangings": int(w[14])}


class _SlaveView(SimControl):
    """SimControl.slave(addr): requests go through the parent's socket."""

    def __init__(self, parent: SimControl, addr: int):
        self._parent = parent
        self.addr = addr
        self._prefix = "%02X/" % addr
        self._at = "@%02X" % addr

    def requests(self, lines: List[str]) -> List[str]:
        return self._parent.requests(lines)

    def close(self) -> None:
        pass

    def rx(self, cycle: int, data: bytes) -> int:
        raise SimControlError("rx: only the gateway's serial line reaches the PC")

    def rx_after(self, cycles: int, data: bytes) -> int:
        raise SimControlError("rx: only the gateway's serial line reaches the PC")
