"""Make the host package importable without installing it (PYTHONPATH=host),
and let the programs the tests interrupt see Ctrl-C."""

import signal
import sys
from pathlib import Path

HOST = str(Path(__file__).resolve().parents[1] / "host")
if HOST not in sys.path:
    sys.path.insert(0, HOST)

# A run started in the background by a non-interactive shell (`make test &`)
# inherits SIGINT ignored, and an ignored signal stays ignored across exec:
# every program a test interrupts as Ctrl-C does (orfa sim, console, adc
# --watch, dash, examples/robot.py) ran on until the test's timeout. With a
# handler here instead, they start with SIGINT as at a terminal.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
