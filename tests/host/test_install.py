"""`pip install .` in a fresh venv (no system site packages): the `orfa`
command, the simulator and the firmware inside the package, the pytest
plugin loaded by its entry point, and the one-line errors when something is
missing. Everything runs from a directory outside the repository.

The venv gets its packages from a wheelhouse kept in build/pip/wheelhouse
(filled once through pip's configured index, then used offline), and builds
orfa with `--no-build-isolation` against the venv's own setuptools; a plain
`pip install .` (isolated build, setuptools from the index) is the same
setup.py (docs/simulator.md, "Finding the simulator").
"""

import filecmp
import os
import shutil
import signal
import subprocess
import sys
import venv
from pathlib import Path

import pytest
import serial

from orfa import boardmap
from orfa.boardmap import BOARDS

ROOT = Path(__file__).resolve().parents[2]
WHEELHOUSE = ROOT / "build" / "pip" / "wheelhouse"
#: setuptools: a venv of Python 3.12 and later has none to build with;
#: wheel: setuptools older than 70.1 builds wheels with it
DEPS = ["pyserial", "pytest", "setuptools", "wheel"]
SAMPLE = ROOT / "tests" / "sim" / "plugin_sample.py"


def clean_env(**extra):
    """The environment without what points into the work tree or at a
    simulator (PYTHONPATH, ORFA_*), nor pytest settings of this run."""
    env = {k: v for k, v in os.environ.items()
           if k != "PYTHONPATH" and not k.startswith(("ORFA_", "PYTEST_", "VIRTUAL_ENV"))}
    env.update(extra)
    return env


def run(cmd, cwd, env=None, timeout=120):
    return subprocess.run([str(c) for c in cmd], cwd=str(cwd), env=env or clean_env(),
                          capture_output=True, text=True, timeout=timeout)


def fill_wheelhouse():
    marker = WHEELHOUSE / "complete"
    if marker.is_file() and marker.read_text().split() == DEPS:
        return
    r = run([sys.executable, "-m", "pip", "download", "-q", "--only-binary", ":all:",
             "-d", WHEELHOUSE] + DEPS, cwd=ROOT)
    if r.returncode != 0:
        pytest.fail("cannot fetch %s into %s through pip's index: %s"
                    % (", ".join(DEPS), WHEELHOUSE, r.stderr.strip()), pytrace=False)
    (WHEELHOUSE / "complete").write_text("\n".join(DEPS) + "\n")


class Venv:
    def __init__(self, path: Path):
        self.path = path
        self.bin = path / "bin"
        venv.EnvBuilder(with_pip=True, system_site_packages=False).create(str(path))
        self.site = Path(self.python("-c", "import sysconfig; print(sysconfig.get_paths()['platlib'])")
                         .stdout.strip())

    def python(self, *args, **kw):
        return run([self.bin / "python"] + list(args), cwd=self.path, **kw)

    def pip(self, *args, env=None):
        return run([self.bin / "python", "-m", "pip", "--no-cache-dir",
                    "--disable-pip-version-check"] + list(args), cwd=self.path, env=env,
                   timeout=300)

    def pip_offline(self, *args, env=None):
        return self.pip("install", "--no-index", "--find-links", WHEELHOUSE, *args, env=env)


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """A fresh venv with `pip install .` of the work tree."""
    fill_wheelhouse()
    v = Venv(tmp_path_factory.mktemp("venv") / "v")
    r = v.pip_offline(*DEPS)
    assert r.returncode == 0, r.stderr
    r = v.pip_offline("--no-build-isolation", ROOT)
    assert r.returncode == 0, r.stdout + r.stderr
    return v


def test_the_command_is_installed(installed, tmp_path):
    r = run([installed.bin / "orfa", "--help"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("usage: orfa ")


def test_simulator_and_firmware_are_in_the_package(installed, tmp_path):
    code = ("import orfa, orfa.sim as s\n"
            "print(orfa.__file__)\n"
            "print(s.sim_path())\n"
            "for b in s.BOARDS:\n"
            "    for m in ('gate', 'slave'):\n"
            "        print(s.firmware_path(b, m))\n"
            "print(s.slave_firmware_path('m128s', 0x10))\n"
            "print(s.slave_firmware_path('m32d', 0x12))\n"
            "from orfa import boardmap\n"
            "print(boardmap.load('m32d').name)\n")
    r = run([installed.bin / "python", "-c", code], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    module, sim, *elfs, name = r.stdout.splitlines()
    module, sim, elfs = Path(module), Path(sim), [Path(elf) for elf in elfs]
    assert name == boardmap.load("m32d").name     # the board map is in the package too
    package = installed.site / "orfa"
    assert module == package / "__init__.py"
    assert sim == package / "_sim" / "orfa-sim" and os.access(str(sim), os.X_OK)
    assert filecmp.cmp(str(sim), str(ROOT / "build" / "sim" / "orfa-sim"), shallow=False)
    want = [package / "_firmware" / ("%s-%s" % (b, m)) / "orfa.elf"
            for b in BOARDS for m in ("gate", "slave")]
    want += [package / "_firmware" / "robot" / "m128s-0x10" / "orfa.elf",
             package / "_firmware" / "robot" / "m32d-0x12" / "orfa.elf"]
    assert elfs == want
    for elf in want:
        built = ROOT / "build" / elf.relative_to(package / "_firmware")
        assert filecmp.cmp(str(elf), str(built), shallow=False), elf
        if elf.parent.parent.name != "robot":
            assert filecmp.cmp(str(elf.with_suffix(".hex")), str(built.with_suffix(".hex")),
                               shallow=False)
    # the wheel says it is for this platform, not pure Python
    wheel = (installed.site / "orfa-0.1.0.dist-info" / "WHEEL").read_text()
    assert "Root-Is-Purelib: false" in wheel and "Tag: py3-none-linux_" in wheel, wheel


@pytest.mark.parametrize("args,requests", [
    ([], [(b"V\n", b"V1.1\r\n")]),
    # a robot: the slave's ELF from the package (the test robot's at 0x10)
    (["--slave", "m128s:0x10"], [(b"S 10 P\n", b"SWP\r\n"), (b"S 12 P\n", b"ERROR 06\r\n")]),
])
def test_orfa_sim_answers_on_its_port(installed, tmp_path, args, requests):
    proc = subprocess.Popen([str(installed.bin / "orfa"), "sim", "--board", "m32d"] + args,
                            cwd=str(tmp_path), env=clean_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        port = proc.stdout.readline().strip()
        assert port, proc.stderr.read() if proc.poll() is not None else "no port printed"
        with serial.serial_for_url(port, baudrate=115200, timeout=10) as link:
            for request, reply in requests:
                link.write(request)
                assert link.read_until(b"\r\n") == reply
    finally:
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=10)
    assert proc.returncode == 0, err
    assert not os.path.exists(port)       # the simulator removed its link


def test_a_users_tests_run_with_the_plugin(installed, tmp_path):
    shutil.copy(str(SAMPLE), str(tmp_path / "test_robot_code.py"))
    r = run([installed.bin / "pytest", "-p", "no:cacheprovider", "test_robot_code.py"],
            cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.strip().splitlines()[-1].startswith("===") and " 9 passed" in r.stdout, r.stdout
    # loaded by its entry point: no -p, no conftest
    r = run([installed.bin / "pytest", "--help"], cwd=tmp_path)
    assert "--orfa-board={m32d,m128s}" in r.stdout


def test_plot_without_matplotlib_names_the_extra(installed, tmp_path):
    # the venv has only pyserial and pytest: orfa plot says what to install
    # before it starts a board
    r = run([installed.bin / "orfa", "--sim", "m32d", "plot", "--do", "servo 3 1500",
             "-o", tmp_path / "x.png"], cwd=tmp_path)
    assert (r.returncode, r.stdout) == (2, "")
    assert r.stderr == "orfa: orfa plot needs matplotlib: pip install 'orfa[plot]'\n"
    assert not (tmp_path / "x.png").exists()


def test_missing_simulator_is_one_line(installed, tmp_path):
    nowhere = tmp_path / "nowhere" / "orfa-sim"
    r = run([installed.bin / "orfa", "sim", "--board", "m32d"], cwd=tmp_path,
            env=clean_env(ORFA_SIM=str(nowhere)))
    assert r.returncode == 2
    assert r.stdout == ""
    assert r.stderr == ("orfa: %s is missing: ORFA_SIM=%s set (ORFA_SIM names an orfa-sim,"
                        " ORFA_FIRMWARE a directory laid out like the repository's build/;"
                        " unset to use the installed copies)\n" % (nowhere, nowhere)), r.stderr


def test_install_without_the_simulator(tmp_path):
    """ORFA_SKIP_BUILD=1: the host library alone, a pure wheel; `orfa sim`
    then says so in one line."""
    fill_wheelhouse()
    v = Venv(tmp_path / "v")
    assert v.pip_offline("wheel").returncode == 0
    r = v.pip_offline("--no-build-isolation", ROOT, env=clean_env(ORFA_SKIP_BUILD="1"))
    assert r.returncode == 0, r.stdout + r.stderr
    package = v.site / "orfa"
    assert (package / "sim.py").is_file()
    assert not (package / "_sim").exists() and not (package / "_firmware").exists()
    assert "Root-Is-Purelib: true" in (v.site / "orfa-0.1.0.dist-info" / "WHEEL").read_text()
    r = run([v.bin / "orfa", "sim"], cwd=tmp_path)
    assert r.returncode == 2
    assert r.stderr == ("orfa: %s is missing: this orfa was installed without the simulator"
                        " (ORFA_SKIP_BUILD=1): reinstall it from the source tree after"
                        " running tools/setup.sh there, or set ORFA_SIM and ORFA_FIRMWARE\n"
                        % (package / "_sim" / "orfa-sim")), r.stderr


def test_missing_toolchain_stops_the_install_with_one_message(installed, tmp_path):
    """No make, gcc, avr-gcc on PATH: the build says what is missing and
    what to do, and nothing is installed."""
    r = installed.pip_offline("--no-build-isolation", "--target", tmp_path / "t", ROOT,
                              env=clean_env(PATH=str(installed.bin)))
    assert r.returncode != 0
    out = r.stdout + r.stderr
    message = ("orfa: cannot build the simulator and the firmware, missing: make, gcc,"
               " avr-gcc (gcc-avr), avr-objcopy (binutils-avr); run tools/setup.sh (it"
               " installs them on Debian), or set ORFA_SKIP_BUILD=1 to install the host"
               " library without the simulator")
    assert message in out, out
    assert "Traceback" not in out, out
    assert not (tmp_path / "t" / "orfa").exists()


def test_orfa_flash_writes_the_packages_hex(installed, tmp_path):
    """orfa flash finds the build through the same lookup: the package's copy."""
    r = run([installed.bin / "orfa", "flash", "--dry-run", "--board", "m128s", "--mode", "slave"],
            cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    hex_path = installed.site / "orfa" / "_firmware" / "m128s-slave" / "orfa.hex"
    assert r.stdout == "avrdude -c usbasp -p %s -U flash:w:%s:i\n" % (
        boardmap.load("m128s").avrdude_part, hex_path), r.stdout
    # a gateway for a fast rate: the package's build of it (make gate-rates)
    r = run([installed.bin / "orfa", "flash", "--dry-run", "--rate", "460800"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    hex_path = installed.site / "orfa" / "_firmware" / "m32d-gate-460800" / "orfa.hex"
    assert r.stdout == "avrdude -c usbasp -p m32 -U flash:w:%s:i\n" % hex_path, r.stdout


def test_issue_commands_run_from_the_venv(installed, tmp_path):
    """The commands a new user tries first, from outside the repository."""
    from orfa import boardmap
    orfa = installed.bin / "orfa"
    r = run([orfa, "--sim", "m32d", "scan"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[0].split() == list("0123456789abcdef")
    assert "50: -- -- -- -- -- 55 --" in r.stdout         # the gateway itself, 0xAA
    r = run([orfa, "--sim", "m32d", "drivers"], cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    rows = [line.split() for line in r.stdout.splitlines()[2:]]
    assert [(int(row[0], 16), row[1]) for row in rows] == \
        [(d.uid, d.name) for d in boardmap.load("m32d").drivers]
    r = run([orfa, "--sim", "m32d", "servo", "3", "1500"], cwd=tmp_path)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    # the fast rates: the package's gateways built for them (make gate-rates)
    for rate in ("230400", "460800"):
        r = run([orfa, "--sim", "m128s", "--baud", rate, "request", "V"], cwd=tmp_path)
        assert (r.returncode, r.stdout, r.stderr) == (0, "V1.1\n", "")
    r = run([orfa, "--sim", "m128s", "--baud", "57600", "version"], cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.startswith("orfa: no m128s gateway at 57600 baud: ")


def test_dash_page_is_in_the_package_and_flask_is_asked_for(installed, tmp_path):
    """The dashboard's page ships with the package; the venv has no Flask
    (the extra orfa[dash] was not asked for), so `orfa dash` says which
    extra to install."""
    static = installed.site / "orfa" / "dash" / "static"
    for name in ("index.html", "dash.js", "dash.css"):
        assert filecmp.cmp(str(static / name),
                           str(ROOT / "host" / "orfa" / "dash" / "static" / name), shallow=False)
    r = run([installed.bin / "orfa", "dash", "--sim", "m32d"], cwd=tmp_path)
    assert (r.returncode, r.stdout, r.stderr) == (
        2, "", "orfa: orfa dash needs Flask: pip install 'orfa[dash]'\n")


def readme_python_examples():
    """README's Python examples: each indented block that imports orfa, as
    (its code, the comments of its print lines: what it prints)."""
    import re
    text = (ROOT / "README.md").read_text()
    out = []
    for block in re.findall(r"\n\n((?:    .*\n|\n(?=    ))+)", text):
        code = "\n".join(line[4:] for line in block.splitlines())
        if not re.search(r"^(from orfa|import orfa)", code, re.M):
            continue
        shown = [line.split("#", 1)[1].strip() for line in code.splitlines()
                 if line.lstrip().startswith("print(") and "#" in line]
        out.append((code, shown))
    return out


def test_readme_python_examples_run_from_the_installed_package(installed, tmp_path):
    """Every Python example of README.md, as a new user pastes it, run by the
    venv's Python in a directory outside the repository: it runs (the
    firmware it needs comes from the package, not from build/), and prints
    what its comments show. An example for a real port gets a simulated
    board's port instead."""
    from orfa.sim import SimBoard
    examples = readme_python_examples()
    assert len(examples) >= 3 and all(shown for _, shown in examples)
    board = None
    try:
        for i, (code, shown) in enumerate(examples):
            if "/dev/ttyUSB0" in code:
                if board is None:
                    board = SimBoard("m32d", trace=False).start()
                code = code.replace("/dev/ttyUSB0", board.port)
            script = tmp_path / ("example_%d.py" % i)
            script.write_text(code + "\n")
            r = run([installed.bin / "python", script], cwd=tmp_path)
            assert (r.returncode, r.stderr) == (0, ""), code
            assert r.stdout.splitlines() == shown, code
    finally:
        if board is not None:
            board.stop()
