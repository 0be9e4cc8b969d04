"""Make the host package importable without installing it (PYTHONPATH=host)."""

import sys
from pathlib import Path

HOST = str(Path(__file__).resolve().parents[1] / "host")
if HOST not in sys.path:
    sys.path.insert(0, HOST)
