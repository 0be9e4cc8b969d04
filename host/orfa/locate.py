"""Where the simulator and the firmware ELFs are (docs/simulator.md, "Finding
the simulator").

Looked up in this order, the first that applies wins:

1. `ORFA_SIM`: the path of an orfa-sim; `ORFA_FIRMWARE`: a directory laid out
   like the repository's build/ (`<board>-<mode>/orfa.elf`,
   `robot/<board>-0x<ADDR>/orfa.elf`). A setting is final: a file missing
   there is an error, never a fall-back to something else.
2. The installed package's data (`pip install .` copies them in):
   `orfa/_sim/orfa-sim` and `orfa/_firmware/`, laid out like build/.
3. The repository's build/ when this package runs from the work tree
   (`PYTHONPATH=host`, or `pip install -e .`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable, List, Optional

from .boardmap import BOARDS

PACKAGE_DIR = Path(__file__).resolve().parent
#: The repository root (host/orfa/../..); meaningful only in a work tree.
REPO_ROOT = PACKAGE_DIR.parents[1]
#: The installed package's copies (setup.py puts them there).
PACKAGE_SIM = PACKAGE_DIR / "_sim" / "orfa-sim"
PACKAGE_FIRMWARE = PACKAGE_DIR / "_firmware"
SIM_ENV = "ORFA_SIM"
FIRMWARE_ENV = "ORFA_FIRMWARE"


def in_work_tree() -> bool:
    """Whether this package is the repository's host/orfa (not an installed copy)."""
    return PACKAGE_DIR.parent.name == "host" and (REPO_ROOT / "Makefile").is_file()


def _env_path(name: str) -> Optional[Path]:
    value = os.environ.get(name, "")
    return Path(value).expanduser() if value else None


def firmware_dirs() -> List[Path]:
    """The directories laid out like build/ that firmware is looked up in, in order."""
    env = _env_path(FIRMWARE_ENV)
    if env is not None:
        return [env]
    dirs = [PACKAGE_FIRMWARE] if PACKAGE_FIRMWARE.is_dir() else []
    if in_work_tree():
        dirs.append(REPO_ROOT / "build")
    return dirs or [PACKAGE_FIRMWARE]


def sim_path() -> Path:
    """The orfa-sim to run (it may not exist: see missing_hint)."""
    env = _env_path(SIM_ENV)
    if env is not None:
        return env
    candidates = [PACKAGE_SIM]
    if in_work_tree():
        candidates.append(REPO_ROOT / "build" / "sim" / "orfa-sim")
    return _first_file(candidates)


def firmware_path(board: str, mode: str = "gate") -> Path:
    """The firmware ELF of `board` in `mode` (gate or slave)."""
    return _first_file([d / ("%s-%s" % (board, mode)) / "orfa.elf" for d in firmware_dirs()])


def make_gateway(board: str, baud, build: str, *make_vars: str) -> Path:
    """`make BOARD=<board> MODE=gate BAUD=<baud> BUILD=<build>` (and
    `make_vars`, e.g. FW_DEBUG=-g) in the work tree; the ELF. ValueError
    with one line when make refuses (its reason: 921600, a rate the line
    has not). One make at a time in the work tree: two programs that ask
    for the same build at once (two `orfa sim --baud 460800`) would write
    its files together, and one of them fail."""
    import fcntl
    import subprocess
    lock_path = REPO_ROOT / "build" / ".make-gateway.lock"
    lock_path.parent.mkdir(parents=True, exist_ok=True)
    with open(lock_path, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        made = subprocess.run(["make", "-s", "--no-print-directory", "BOARD=" + board,
                               "MODE=gate", "BAUD=%s" % baud, "BUILD=" + build] + list(make_vars),
                              cwd=REPO_ROOT, capture_output=True, text=True)
    if made.returncode:
        why = (made.stderr.strip().splitlines() or ["make failed"])[-1]
        why = why.split("*** ", 1)[-1].replace("  Stop.", "")
        raise ValueError("no %s gateway at %s baud: %s" % (board, baud, why))
    return REPO_ROOT / build / "orfa.elf"


def gateway_firmware(board: str, baud) -> Path:
    """The gateway ELF of `board` that talks at `baud` (a rate, or "auto":
    the autobaud build): at the protocol's default rate the default build
    (firmware_path), else <board>-gate-<baud>/orfa.elf in the firmware
    directories. In the work tree (ORFA_FIRMWARE unset) that one is made
    (make_gateway) when missing or out of date. ValueError with one line
    when there is none for that rate."""
    from .protocol import DEFAULT_BAUD
    if baud == DEFAULT_BAUD:
        return firmware_path(board, "gate")
    name = "%s-gate-%s" % (board, baud)
    if _env_path(FIRMWARE_ENV) is None and in_work_tree():
        return make_gateway(board, baud, "build/" + name)
    path = _first_file([d / name / "orfa.elf" for d in firmware_dirs()])
    if not path.is_file():
        raise ValueError("no %s gateway at %s baud: %s is not there (make BOARD=%s MODE=gate "
                         "BAUD=%s BUILD=build/%s in the source tree, then point %s at its "
                         "build/)" % (board, baud, path, board, baud, name, FIRMWARE_ENV))
    return path


def slave_firmware_path(board: str, addr: int) -> Path:
    """The slave build for `board` at bus address `addr`: the test robot's
    (`make robot`, robot/<board>-0x<ADDR>/) when there is one, else
    <board>-slave/ (`make BOARD=<board> MODE=slave ADDR=<addr>`; the
    address is compiled in, and the simulator warns when it differs)."""
    for d in firmware_dirs():
        for path in (d / "robot" / ("%s-0x%02X" % (board, addr)) / "orfa.elf",
                     d / ("%s-slave" % board) / "orfa.elf"):
            if path.is_file():
                return path
    return firmware_dirs()[0] / ("%s-slave" % board) / "orfa.elf"


def _first_file(candidates: List[Path]) -> Path:
    """The first candidate that is a file; the last one when none is (in the
    work tree, the repository's build/, which the hint then tells to make)."""
    for path in candidates:
        if path.is_file():
            return path
    return candidates[-1]


def missing_builds(boards: Iterable[str] = BOARDS) -> List[Path]:
    """The simulator and gateway firmware files that are not there."""
    paths = [sim_path()] + [firmware_path(b) for b in boards]
    return [path for path in paths if not path.is_file()]


def build_hint() -> str:
    """What to do about a missing simulator or firmware, where we are."""
    settings = ["%s=%s" % (name, os.environ[name]) for name in (SIM_ENV, FIRMWARE_ENV)
                if _env_path(name) is not None]
    if settings:
        return ("%s set (%s names an orfa-sim, %s a directory laid out like the"
                " repository's build/; unset to use the installed copies)"
                % (" and ".join(settings), SIM_ENV, FIRMWARE_ENV))
    if in_work_tree():
        return "run `make all-boards sim` in %s (`make robot` for the test robot)" % REPO_ROOT
    if PACKAGE_SIM.is_file():
        return ("not part of the installed orfa (it has the builds of `make all-boards"
                " gate-rates robot sim`): give the ELF's path, or set %s" % FIRMWARE_ENV)
    return ("this orfa was installed without the simulator (ORFA_SKIP_BUILD=1):"
            " reinstall it from the source tree after running"
            " tools/setup.sh there, or set %s and %s" % (SIM_ENV, FIRMWARE_ENV))
