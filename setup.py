"""`pip install .`: the host package with the simulator and the firmware it runs.

The metadata is in pyproject.toml; this file only adds the build step. The
wheel's build_py runs `make` in this source tree (incremental: quick when
build/ is up to date) and copies into the package

    orfa/_sim/orfa-sim                        build/sim/orfa-sim
    orfa/_firmware/<board>-<mode>/orfa.elf    build/<board>-<mode>/ (and .hex)
    orfa/_firmware/<board>-gate-<rate>/       build/<board>-gate-<rate>/ (make gate-rates:
                                              230400, 460800, auto)
    orfa/_firmware/robot/<board>-<addr>/      build/robot/ (the test robot's slaves)

where orfa.locate finds them. The simulator is a program for this machine, so
the wheel is tagged for the platform (py3-none-<platform>).

ORFA_SKIP_BUILD=1 installs the host library alone (a pure wheel, no
simulator). An editable install (`pip install -e .`) builds nothing: the
package then runs from host/ and uses the repository's build/.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

try:                                   # setuptools >= 70.1 has its own
    from setuptools.command.bdist_wheel import bdist_wheel
except ImportError:                    # older: the wheel package's
    try:
        from wheel.bdist_wheel import bdist_wheel
    except ImportError:
        bdist_wheel = None

ROOT = Path(__file__).resolve().parent
SKIP = os.environ.get("ORFA_SKIP_BUILD", "") not in ("", "0")
# Every board of boards/, each in the Makefile's MODES.
BOARDS = sorted(p.parent.name for p in (ROOT / "boards").glob("*/board.mk"))
MODES = ("gate", "slave")
MAKE_GOALS = ["all-boards", "gate-rates", "robot", "build/sim/orfa-sim"]
SETUP_HINT = ("run tools/setup.sh (it installs them on Debian), or set"
              " ORFA_SKIP_BUILD=1 to install the host library without the simulator")

# What the build needs: (what, found?)
TOOLCHAIN = [
    ("make", lambda: shutil.which("make")),
    ("gcc", lambda: shutil.which("gcc")),
    ("avr-gcc (gcc-avr)", lambda: shutil.which("avr-gcc")),
    ("avr-objcopy (binutils-avr)", lambda: shutil.which("avr-objcopy")),
    ("avr-libc", lambda: Path("/usr/lib/avr/include/avr/io.h").is_file()),
    ("simavr's headers (libsimavr-dev)", lambda: Path("/usr/include/simavr/sim_avr.h").is_file()),
    ("libelf's headers (libelf-dev)", lambda: Path("/usr/include/libelf.h").is_file()),
]


def fail(message):
    """One line on stderr (pip shows it), no traceback."""
    raise SystemExit("orfa: " + message)


def build_artefacts():
    """Run make in the source tree; the files to ship, {package path: build path}."""
    if not (ROOT / "Makefile").is_file():
        fail("%s has no Makefile: build from the repository (or set ORFA_SKIP_BUILD=1)" % ROOT)
    missing = [what for what, found in TOOLCHAIN if not found()]
    if missing:
        fail("cannot build the simulator and the firmware, missing: %s; %s"
             % (", ".join(missing), SETUP_HINT))
    jobs = [] if "-j" in os.environ.get("MAKEFLAGS", "") else ["-j%d" % min(4, os.cpu_count() or 1)]
    cmd = ["make", "--no-print-directory"] + jobs + MAKE_GOALS
    print("orfa: building in %s: %s" % (ROOT, " ".join(cmd)), flush=True)
    status = subprocess.call(cmd, cwd=str(ROOT), stdout=sys.stderr)
    if status != 0:
        fail("`%s` failed in %s (exit %d; its output is above)" % (" ".join(cmd), ROOT, status))
    build = ROOT / "build"
    files = {"_sim/orfa-sim": build / "sim" / "orfa-sim"}
    # the rates `make gate-rates` built (the Makefile's GATE_RATES)
    asked = subprocess.run(["make", "-s", "--no-print-directory", "print-gate-rates"], cwd=str(ROOT),
                           capture_output=True, text=True)
    rates = asked.stdout.split()
    if asked.returncode or not rates:
        fail("`make print-gate-rates` failed in %s: %s" % (ROOT, asked.stderr.strip() or "no rates"))
    for board in BOARDS:
        for mode in MODES:
            for name in ("orfa.elf", "orfa.hex"):
                files["_firmware/%s-%s/%s" % (board, mode, name)] = build / ("%s-%s" % (board, mode)) / name
        for rate in rates:
            for name in ("orfa.elf", "orfa.hex"):
                rel = "%s-gate-%s/%s" % (board, rate, name)
                files["_firmware/" + rel] = build / rel
    for elf in sorted((build / "robot").glob("*/orfa.elf")):
        files["_firmware/robot/%s/orfa.elf" % elf.parent.name] = elf
    absent = [str(path) for path in files.values() if not path.is_file()]
    if absent:
        fail("make succeeded but did not make %s" % ", ".join(absent))
    return files


class BuildWithSimulator(build_py):
    """build_py, then the simulator and the firmware into the package."""

    def run(self):
        editable = getattr(self, "editable_mode", False)
        # make first: a missing toolchain is the first and last thing said
        files = build_artefacts() if not (SKIP or editable) else {}
        super().run()
        if editable:
            return
        # build/pip outlives a build: no copy from an earlier one stays
        for rel in ("_sim", "_firmware"):
            self.remove_tree(Path(self.build_lib) / "orfa" / rel)
        for rel, source in files.items():
            target = Path(self.build_lib) / "orfa" / rel
            self.mkpath(str(target.parent))
            self.copy_file(str(source), str(target))    # keeps the x bit


    def remove_tree(self, path):
        if path.exists():
            self.announce("removing %s" % path, level=2)
            shutil.rmtree(str(path))


class PlatformDistribution(Distribution):
    """Not pure Python when it carries the simulator: a platform wheel."""

    def has_ext_modules(self):
        return not SKIP


cmdclass = {"build_py": BuildWithSimulator}

if bdist_wheel is not None:
    class PlatformWheel(bdist_wheel):
        """py3-none-<platform>: no extension module, so any Python 3 on
        this platform (the simulator is a program, not a module)."""

        def get_tag(self):
            python, abi, plat = super().get_tag()
            return ("py3", "none", plat) if not SKIP else (python, abi, plat)

    cmdclass["bdist_wheel"] = PlatformWheel

setup(
    distclass=PlatformDistribution,
    cmdclass=cmdclass,
    # setuptools' default build/ is the firmware's build directory
    options={"build": {"build_base": "build/pip"}},
)
