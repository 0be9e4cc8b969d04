"""One client per driver (board.gpio, board.servo, ...), each a thin layer
of register accesses over orfa.board.Board. Importing this package gives
each driver's Board attribute its client (orfa.board.CLIENTS); importing
orfa does that."""

from ..board import CLIENTS
from .adc import Adc
from .gpio import Gpio
from .motor import Motor
from .servo import Servo
from .spi import Spi

CLIENTS.update(adc=Adc, gpio=Gpio, motor=Motor, servo=Servo, spi=Spi)
