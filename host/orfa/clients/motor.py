"""board.motor: the motor driver's PWMn and DIRn registers as signed duties."""

from __future__ import annotations

from typing import List, Optional

from ..errors import PinBusyError

#: A motor's duty is -MAX_DUTY..MAX_DUTY, its sign the direction (PWMn is a byte).
MAX_DUTY = 255
#: The range as the messages and help texts give it.
DUTY_RANGE = "-%d..%d" % (MAX_DUTY, MAX_DUTY)


def is_duty(value) -> bool:
    """True for a duty a motor takes: an int in -MAX_DUTY..MAX_DUTY. The one
    check of the range: Motor's, `orfa motor`'s and the dashboard's."""
    return isinstance(value, int) and not isinstance(value, bool) \
        and -MAX_DUTY <= value <= MAX_DUTY


class Motor:
    def __init__(self, board):
        self.board = board
        regs = board.board_map("motor").driver("motor").registers
        #: motors on the board (the map's PWMn registers): 2 on an M32-D
        self.count: int = sum(1 for r in regs if r.startswith("PWM"))

    def _n(self, n: int) -> int:
        if not isinstance(n, int) or isinstance(n, bool) or not 1 <= n <= self.count:
            raise ValueError("motor %r: motors are 1..%d" % (n, self.count))
        return n

    @staticmethod
    def _duty(duty: int) -> int:
        if not is_duty(duty):
            raise ValueError("duty must be %s (sign: direction), not %r" % (DUTY_RANGE, duty))
        return duty

    def set(self, n: int, duty: int) -> None:
        """Motor n (1 or 2) at duty -255..255 (sign: direction, 1 backward on
        DIRn). The registers are read, then written back whole from PWM1
        with motor n changed: one write, all of it or none (a refused PWM,
        pin busy, leaves the direction too), the motors in the same period."""
        n, duty = self._n(n), self._duty(duty)
        duties = self.duties()
        duties[n - 1] = duty
        self._write(duties, changed=n)

    def set_all(self, *duties: int) -> None:
        """Every motor at once, one write from PWM1 (`80 60 00 01`): both
        change in the same PWM period."""
        if len(duties) != self.count:
            raise ValueError("set_all takes %d duties, not %d" % (self.count, len(duties)))
        self._write(tuple(self._duty(d) for d in duties))

    def _write(self, duties, changed: Optional[int] = None) -> None:
        data = [abs(d) for d in duties] + [1 if d < 0 else 0 for d in duties]
        try:
            self.board.write("motor", "PWM1", data)
        except PinBusyError as exc:
            raise self._busy(exc, duties, changed if changed and duties[changed - 1] else None
                             ) from exc.__cause__        # the ERROR 07, as the board's

    def _busy(self, exc: PinBusyError, duties, changed: Optional[int] = None) -> PinBusyError:
        """A PIN_BUSY refusal (the write starts at PWM1, so the board names
        PWM1) named after the motor whose PWM line a servo channel holds:
        `changed` when set() changed only that one, else each motor given a
        duty whose line a servo channel can hold. Nothing is read to find
        out: a read would overwrite the status register's PIN_BUSY."""
        bmap = self.board.board_map("motor")
        servo_pins = {(q.port, q.bit) for q in bmap.pins_of("SERVO")}
        motors = [changed] if changed else [n for n, d in enumerate(duties, 1) if d]
        busy = [n for n in motors
                if any((pin.port, pin.bit) in servo_pins
                       for pin in bmap.pins_of("MOTOR_PWM", n - 1))]
        if not busy:
            return exc
        return type(exc)(exc.status, exc.addr, "motor " + "/".join("PWM%d" % n for n in busy),
                         "write", code=exc.code)

    def get(self, n: int) -> int:
        """Motor n's signed duty (negative: backward)."""
        return self.duties()[self._n(n) - 1]

    def duties(self) -> List[int]:
        """Every motor's signed duty, from one read of all the registers."""
        data = self.board.read("motor", "PWM1", 2 * self.count)
        pwm, dirs = data[:self.count], data[self.count:]
        return [-d if r else d for d, r in zip(pwm, dirs)]

    def stop(self, n: Optional[int] = None) -> None:
        """PWM 0 for motor n, or every motor (one write); directions kept."""
        if n is None:
            self.board.write("motor", "PWM1", [0] * self.count)
        else:
            self.board.write("motor", "PWM%d" % self._n(n), [0])
