"""One board's state as plain data (JSON-ready), read with the typed API.

What a board has comes from its introspection and its board map: the
drivers present, servo channels, motors, GPIO ports and which pins the map
gives a fixed function. Nothing here knows a count or a pin of its own.
"""

from __future__ import annotations

from typing import Dict, List, Optional

from .. import boards
from ..board import Board
from ..clients.servo import ServoRange

#: The angle shown next to a width: the manual's servo (+-75 degrees at
#: 1000/2000 us), as `orfa servo --angle` without --range.
RANGE = ServoRange()

#: Reset causes in the order the page lists them.
CAUSES = tuple(boards.RESET_CAUSES)


def address_key(addr: int) -> str:
    """A board's key in URLs and snapshots: its 8-bit address, two hex digits."""
    return "%02X" % addr


def pin_functions(board_map) -> Dict[str, List[str]]:
    """{"PD5": ["MOTOR_PWM 0", "SERVO 14"]}: what the map says each pin may be."""
    out: Dict[str, List[str]] = {}
    for pin in board_map.pins:
        out.setdefault(pin.label, []).append("%s %d" % (pin.function, pin.index))
    return out


def describe(board: Board) -> Dict[str, object]:
    """What does not change while the page runs: address, model, drivers,
    servo channels with their pins, motors, GPIO ports, ADC port."""
    m = board.map
    info: Dict[str, object] = {
        "addr": address_key(board.addr),
        "role": "gateway" if board.is_local else "slave",
        "board": m.board, "name": m.name,
        "drivers": [board.driver_name(r.uid) or "%04X" % r.uid for r in board.drivers],
        "limits": {"servo_min_us": m.limits["servo_min_us"],
                   "servo_max_us": m.limits["servo_max_us"]},
    }
    servo_pins = {pin.index: pin.label for pin in m.pins_of("SERVO")}
    if board.has("servo"):
        info["servo_pins"] = [servo_pins.get(ch) for ch in range(board.servo.channels)]
    if board.has("motor"):
        info["motors"] = board.motor.count
    if board.has("gpio"):
        info["gpio_ports"] = board.gpio.ports
        info["pin_functions"] = pin_functions(m)
    if board.has("adc"):
        info["adc_port"] = m.adc_port
    return info


def _servo(board: Board) -> List[Dict[str, object]]:
    return [{"ch": ch, "us": us, "deg": None if us == 0 else round(RANGE.degrees(us), 1)}
            for ch, us in enumerate(board.servo.widths())]


def _motor(board: Board) -> List[Dict[str, object]]:
    return [{"n": n, "duty": duty,
             "direction": "stopped" if duty == 0 else "backward" if duty < 0 else "forward"}
            for n, duty in enumerate(board.motor.duties(), 1)]


def _adc(board: Board) -> Dict[str, object]:
    adc = board.adc
    reference, bits, enabled = adc.config()
    try:
        volts: List[Optional[float]] = [round(v, 4) for v in adc.volts()]
    except ValueError:                  # AREF: its voltage is not known here
        volts = [None] * len(adc.read())
    return {"reference": reference, "bits": bits, "enabled": list(enabled),
            "volts": [v if ch in enabled else None for ch, v in enumerate(volts)]}


def _gpio(board: Board) -> List[Dict[str, object]]:
    gpio = board.gpio
    return [{"port": port, "levels": gpio.read(port), "modes": gpio.modes(port)}
            for port in gpio.ports]


def read(board: Board) -> Dict[str, object]:
    """The board's live values: status, reset cause, failsafe, and each
    driver it has (servo, motor, adc, gpio)."""
    status = board.status()             # first: the result of the access before
    causes = board.reset_cause()
    state: Dict[str, object] = {
        "status": {"code": int(status), "name": status.name, "text": status.text},
        "reset_cause": [c for c in CAUSES if c in causes],
        "failsafe_ms": board.failsafe(),
    }
    for name, reader in (("servo", _servo), ("motor", _motor), ("adc", _adc),
                         ("gpio", _gpio)):
        if board.has(name):
            state[name] = reader(board)
    return state
