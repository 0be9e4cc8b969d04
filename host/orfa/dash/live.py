"""The boards of one Gateway, live: found once, read by one poller thread,
moved by the controls; every read and write holds one lock, so the poller
and the controls (web requests on their own threads) take turns on the line.

    dash = Dashboard(gateway, interval=0.2).start()
    queue = dash.subscribe()          # every new snapshot, latest first
    dash.control("AA", "servo", {"channel": 3, "us": 1700})
    dash.control("AA", "adc", {"channels": [0, 1], "reference": "avcc", "bits": 10})
    dash.close()
"""

from __future__ import annotations

import math
import queue
import threading
import time
from typing import Callable, Dict, List, Optional, Sequence

from .. import protocol as p
from ..board import Board
from ..clients.adc import CHANNELS as ADC_CHANNELS, REFERENCES as ADC_REFERENCES
from ..clients.motor import DUTY_RANGE, is_duty
from ..errors import ControlError, NotFound, Refused, explain  # noqa: F401 (dash.web's)
from ..gateway import Gateway
from . import snapshot


class Dashboard:
    """The boards behind `gateway`: its own, and the ORFA slaves at the
    8-bit addresses `slaves`, or with None those that answer a scan of the
    bus (other devices that answer, an EEPROM, are listed by address)."""

    def __init__(self, gateway: Gateway, interval: float = 0.2,
                 slaves: Optional[Sequence[int]] = None):
        if not interval > 0:
            raise ValueError("the refresh interval must be above 0 s, not %r" % (interval,))
        self.gateway = gateway
        self.interval = interval
        self.slaves = None if slaves is None else [a & 0xFE for a in slaves]
        self.lock = threading.Lock()
        self.boards: Dict[str, Board] = {}
        self.info: Dict[str, Dict[str, object]] = {}
        #: devices that answered the scan but are no ORFA board (address keys)
        self.others: List[str] = []
        self.seq = 0
        self._latest: Optional[Dict[str, object]] = None
        self._subscribers: List["queue.Queue"] = []
        self._subs_lock = threading.Lock()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None

    # --- the boards -------------------------------------------------------------
    def discover(self) -> None:
        """The gateway's own board, then each slave: those named, or each
        address that acknowledges a probe (`orfa scan`) and answers
        introspection with drivers a board map knows. A slave named that
        is no ORFA board raises OrfaError."""
        with self.lock:
            gw = self.gateway
            local = gw.local_address()
            own = Board(gw)
            if own.map is None:
                raise p.OrfaError("the gateway's drivers match no board map (UIDs %s)"
                                  % " ".join("%04X" % r.uid for r in own.drivers))
            found = [own]
            named = self.slaves is not None
            addrs = self.slaves if named else [a << 1 for a in gw.scan()]
            for addr in addrs:
                if addr == local:
                    continue
                board = Board(gw, addr)
                try:
                    known = board.map is not None
                except (p.OrfaError, ValueError) as exc:
                    if named:
                        raise p.OrfaError("0x%02X: no ORFA board answers: %s"
                                          % (addr, explain(exc))) from None
                    known = False
                if known:
                    found.append(board)
                elif named:
                    raise p.OrfaError("0x%02X is no ORFA board: its introspection"
                                      " matches no board map" % addr)
                else:
                    self.others.append(snapshot.address_key(addr))
            for board in found:
                key = snapshot.address_key(board.addr)
                self.boards[key] = board
                self.info[key] = snapshot.describe(board)

    def board(self, key: str) -> Board:
        """The board at `key` ("AA", "10", "0x10")."""
        try:
            addr = int(key, 16)
        except ValueError:
            addr = -1
        found = self.boards.get(snapshot.address_key(addr)) if 0 <= addr <= 0xFF else None
        if found is None:
            raise NotFound("no board at %r here (boards: %s)"
                               % (key, ", ".join(self.boards) or "none"))
        return found

    # --- the poller -------------------------------------------------------------
    def start(self) -> "Dashboard":
        """Find the boards, read them once (latest() has a snapshot from
        now on), then poll them on a thread of its own."""
        if not self.boards:
            self.discover()
        self.poll()
        self._thread = threading.Thread(target=self._run, name="orfa-dash-poller",
                                        daemon=True)
        self._thread.start()
        return self

    def _run(self) -> None:
        while True:
            self._wake.wait(self.interval)
            self._wake.clear()
            if self._stop.is_set():
                return
            self.poll()

    def poll(self) -> Dict[str, object]:
        """Read every board once and publish the snapshot."""
        states = []
        for key, board in list(self.boards.items()):
            try:
                with self.lock:
                    state = snapshot.read(board)
            except (p.OrfaError, OSError) as exc:
                state = {"error": explain(exc)}
            except Exception as exc:       # a bug: shown, and the poller goes on
                state = {"error": "%s: %s" % (type(exc).__name__, exc)}
            states.append(dict(self.info[key], **state))
        self.seq += 1
        snap = {"seq": self.seq, "time": round(time.time(), 3), "interval": self.interval,
                "port": self.gateway.url, "boards": states, "others": list(self.others)}
        self._publish(snap)
        return snap

    def refresh_soon(self) -> None:
        """Poll now rather than at the end of the interval (after a control)."""
        self._wake.set()

    def latest(self) -> Optional[Dict[str, object]]:
        return self._latest

    # --- subscribers (the SSE streams) -------------------------------------------
    def subscribe(self) -> "queue.Queue":
        """A queue that gets each new snapshot (None when the dashboard
        closes); a slow reader skips to the newest."""
        q: "queue.Queue" = queue.Queue(maxsize=1)
        with self._subs_lock:              # no snapshot published in between
            self._subscribers.append(q)
            if self._latest is not None:
                _offer(q, self._latest)
        return q

    def unsubscribe(self, q: "queue.Queue") -> None:
        with self._subs_lock:
            if q in self._subscribers:
                self._subscribers.remove(q)

    def _publish(self, snap: Optional[Dict[str, object]]) -> None:
        with self._subs_lock:              # _offer never blocks
            if snap is not None:
                self._latest = snap
            for q in self._subscribers:
                _offer(q, snap)

    def close(self) -> None:
        """Stop the poller and end every stream."""
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=10)
        self._publish(None)

    # --- the controls -------------------------------------------------------------
    def control(self, key: str, kind: str, body: object) -> Dict[str, object]:
        """Run a control ("servo", "motor", "gpio", "adc") with its JSON body on the
        board at `key`; what was set. NotFound, ControlError (bad
        request), Refused or an OrfaError (the board's answer)."""
        board = self.board(key)
        action = CONTROLS.get(kind)
        if action is None:
            raise NotFound("no control %r (controls: %s)" % (kind, ", ".join(CONTROLS)))
        if not isinstance(body, dict):
            raise ControlError("%s: the body must be a JSON object" % kind)
        info = self.info[snapshot.address_key(board.addr)]
        if kind not in info["drivers"]:
            raise ControlError("%s: the board at %s (%s) has no %s driver"
                               % (kind, info["addr"], info["board"], kind))
        with self.lock:
            done = action(board, info, body)
        self.refresh_soon()
        return dict(done, board=info["addr"])


def _offer(q: "queue.Queue", item) -> None:
    """Put item, dropping what the reader has not taken yet."""
    while True:
        try:
            q.put_nowait(item)
            return
        except queue.Full:
            try:
                q.get_nowait()
            except queue.Empty:
                pass


# --- control bodies ---------------------------------------------------------------

def _number(body: Dict, name: str, lo: float, hi: float, what: str, integer: bool = True):
    if name not in body:
        raise ControlError("%s: %s is missing" % (what, name))
    value = body[name]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or \
            (integer and isinstance(value, float) and not value.is_integer()):
        raise ControlError("%s: %s must be a%s number, not %s"
                           % (what, name, "n integer" if integer else "", _show(value)))
    if not lo <= value <= hi:
        raise ControlError("%s: %s %s is outside %s..%s" % (what, name, _show(value),
                                                           _show(lo), _show(hi)))
    return int(value) if integer else float(value)


#: The most characters of a wrong value that an error message quotes.
SHOW_MAX = 40


def _show(value) -> str:
    """A value as JSON would show it, cut to SHOW_MAX characters (a 100 kB
    string or a list nested 900 deep is named, not echoed)."""
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    try:
        text = "null" if value is None else repr(value) if isinstance(value, str) \
            else str(value)
    except RecursionError:
        text = type(value).__name__
    return text if len(text) <= SHOW_MAX else text[:SHOW_MAX - 3] + "..."


def _check_keys(body: Dict, allowed, what: str) -> None:
    extra = sorted(set(body) - set(allowed))
    if extra:
        raise ControlError("%s: unknown field %s (fields: %s)"
                           % (what, ", ".join(extra), ", ".join(allowed)))


def set_servo(board: Board, info: Dict, body: Dict) -> Dict[str, object]:
    """{"channel": CH, "us": US} (0: off, else the driver's min..max) or
    {"channel": CH, "angle": DEG} (the manual's range)."""
    _check_keys(body, ("channel", "us", "angle"), "servo")
    servo = board.servo
    ch = _number(body, "channel", 0, servo.channels - 1, "servo")
    if ("us" in body) == ("angle" in body):
        raise ControlError("servo: give us or angle (one of them)")
    if "angle" in body:
        lo, hi = sorted((snapshot.RANGE.min_deg, snapshot.RANGE.max_deg))
        us = snapshot.RANGE.width(_number(body, "angle", lo, hi, "servo", integer=False))
    else:
        lo, hi = info["limits"]["servo_min_us"], info["limits"]["servo_max_us"]
        us = _number(body, "us", -math.inf, math.inf, "servo")
        if us != 0 and not lo <= us <= hi:
            raise ControlError("servo: a width of %d us is outside %d..%d (0: off)"
                               % (us, lo, hi))
    servo.set_width(ch, us)
    return {"servo": ch, "us": us}


def set_motor(board: Board, info: Dict, body: Dict) -> Dict[str, object]:
    """{"motor": N, "duty": -255..255} (the sign is the direction; clients.motor.is_duty)."""
    _check_keys(body, ("motor", "duty"), "motor")
    motor = board.motor
    n = _number(body, "motor", 1, motor.count, "motor")
    duty = _number(body, "duty", -math.inf, math.inf, "motor")
    if not is_duty(duty):
        raise ControlError("motor: duty %d is outside %s" % (duty, DUTY_RANGE))
    motor.set(n, duty)
    return {"motor": n, "duty": duty}


def set_gpio(board: Board, info: Dict, body: Dict) -> Dict[str, object]:
    """{"port": "B", "bit": 0..7, "level": 0|1, "output": true|false}, level
    or output or both: the level first (an output's level, an input's
    pull-up), then the direction; read back, a line another function holds
    is Refused."""
    _check_keys(body, ("port", "bit", "level", "output"), "gpio")
    gpio = board.gpio
    port = body.get("port")
    if not isinstance(port, str) or len(port) != 1 or port.upper() not in gpio.ports:
        raise ControlError("gpio: port %s: this board's ports are %s"
                           % (_show(port), ", ".join(gpio.ports)))
    port = port.upper()
    bit = _number(body, "bit", 0, 7, "gpio")
    if "level" not in body and "output" not in body:
        raise ControlError("gpio: give level (0 or 1), output (true or false) or both")
    level = _number(body, "level", 0, 1, "gpio") if "level" in body else None
    output = body.get("output")
    if "output" in body and not isinstance(output, bool):
        raise ControlError("gpio: output must be true or false, not %s" % _show(output))
    mask = 1 << bit
    if level is not None:
        gpio.write(port, 0xFF if level else 0, mask)
    if output is not None:
        gpio.set_modes(port, 0xFF if output else 0, mask)
    modes, levels = gpio.modes(port), gpio.read(port)
    is_output = bool(modes & mask)
    if (output is not None and is_output != output) or \
            (level is not None and is_output and bool(levels & mask) != bool(level)):
        label = "P%s%d" % (port, bit)
        held = info.get("pin_functions", {}).get(label)
        raise Refused("%s did not change: another function holds it%s" % (
            label, " (it may be %s)" % " or ".join(held) if held else ""))
    done: Dict[str, object] = {"port": port, "bit": bit}
    if level is not None:
        done["level"] = level
    if output is not None:
        done["output"] = output
    return done


def set_adc(board: Board, info: Dict, body: Dict) -> Dict[str, object]:
    """{"channels": [0, 3], "reference": "avcc"|"internal"|"aref", "bits": 10|8}:
    the channels to convert (the others off; [] all off), the reference
    (default avcc) and the resolution (default 10); read back, a channel
    the board did not turn on (its pin busy) is Refused."""
    _check_keys(body, ("channels", "reference", "bits"), "adc")
    if "channels" not in body:
        raise ControlError("adc: channels is missing (a list of 0..%d, [] for none)"
                           % (ADC_CHANNELS - 1))
    channels = body["channels"]
    if not isinstance(channels, list):
        raise ControlError("adc: channels must be a list of 0..%d, not %s"
                           % (ADC_CHANNELS - 1, _show(channels)))
    wanted = sorted({_number({"channel": ch}, "channel", 0, ADC_CHANNELS - 1, "adc")
                     for ch in channels})
    reference = body.get("reference", "avcc")
    if reference not in ADC_REFERENCES:
        raise ControlError("adc: reference %s: one of %s"
                           % (_show(reference), ", ".join(ADC_REFERENCES)))
    bits = body.get("bits", 10)
    if isinstance(bits, bool) or bits not in (8, 10):
        raise ControlError("adc: bits must be 8 or 10, not %s" % _show(bits))
    adc = board.adc
    adc.configure(wanted, reference, int(bits))
    got_ref, got_bits, got = adc.config()
    if list(got) != wanted:
        port = info.get("adc_port", "")
        missing = ["P%s%d" % (port, ch) for ch in wanted if ch not in got]
        raise Refused("adc: %s did not turn on: another function holds %s"
                      % (", ".join(missing) or "the channels asked",
                         "it" if len(missing) == 1 else "them"))
    return {"adc": wanted, "reference": got_ref, "bits": got_bits}


CONTROLS: Dict[str, Callable[[Board, Dict, Dict], Dict[str, object]]] = {
    "servo": set_servo, "motor": set_motor, "gpio": set_gpio, "adc": set_adc,
}
