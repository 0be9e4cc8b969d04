"""The pytest plugin (orfa.pytest_plugin): a user's tests in a temporary
directory, run by a pytest of their own with the work tree's plugin
(`-p orfa.pytest_plugin`; installed, the pytest11 entry point loads it:
tests/host/test_install.py)."""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from orfa.boardmap import BOARDS
from orfa.sim import BUILD_HINT, firmware_path, missing_builds

HERE = Path(__file__).resolve().parent
HOST = str(HERE.parents[1] / "host")
SAMPLE = HERE / "plugin_sample.py"


@pytest.fixture(autouse=True)
def builds():
    missing = missing_builds()
    if missing:
        pytest.fail("missing %s: %s" % (", ".join(map(str, missing)), BUILD_HINT), pytrace=False)


def user_pytest(tmp_path, test_text, *args, env=None):
    """Run pytest on `test_text` as test_robot_code.py in tmp_path; (exit
    status, output). Autoloaded plugins off, so only the work tree's orfa
    plugin is in (not an installed one)."""
    (tmp_path / "test_robot_code.py").write_text(test_text)
    run_env = dict(os.environ, PYTHONPATH=HOST, PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
    run_env.update(env or {})
    r = subprocess.run([sys.executable, "-m", "pytest", "-p", "orfa.pytest_plugin",
                        "-p", "no:cacheprovider", "-rA", "test_robot_code.py"] + list(args),
                       cwd=tmp_path, env=run_env, capture_output=True, text=True, timeout=120)
    return r.returncode, r.stdout + r.stderr


def summary(output):
    """{"passed": 7, ...} from pytest's last line."""
    last = output.strip().splitlines()[-1]
    return {word: int(n) for n, word in re.findall(r"(\d+) (\w+)", last)}


def test_sample_user_tests_pass(tmp_path):
    status, out = user_pytest(tmp_path, SAMPLE.read_text())
    assert status == 0, out
    assert summary(out) == {"passed": 9}, out


def test_option_sets_the_default_board(tmp_path):
    text = ("def test_board(orfa_sim_board, orfa_sim_robot):\n"
            "    assert ' atmega128 @ ' in orfa_sim_board.banner\n"
            "    assert ' atmega128 @ ' in orfa_sim_robot.banner\n"
            "    with orfa_sim_board.gateway(timeout=5) as gw:\n"
            "        assert gw.request('V') == 'V1.1'\n")
    status, out = user_pytest(tmp_path, text, "--orfa-board", "m128s")
    assert status == 0, out
    assert summary(out) == {"passed": 1}, out
    # and without it, the M32-D: the same test fails
    status, out = user_pytest(tmp_path, text)
    assert status == 1 and summary(out) == {"failed": 1}, out


def test_bad_option_is_a_usage_error(tmp_path):
    status, out = user_pytest(tmp_path, "def test_x(): pass\n", "--orfa-board", "m8")
    assert status == 4, out
    assert "--orfa-board: invalid choice: 'm8'" in out, out


@pytest.mark.parametrize("decorator,fixture,message", [
    ("@pytest.mark.orfa_board('m8')", "orfa_sim_board",
     "orfa_board: board 'm8' is not one of %s" % ", ".join(BOARDS)),
    ("@pytest.mark.orfa_board('m32d', 'm128s')", "orfa_sim_board",
     "orfa_board takes one board and SimBoard options, not ('m32d', 'm128s')"),
    ("@pytest.mark.orfa_board(colour='red')", "orfa_sim_board",
     "orfa_board: no SimBoard option colour (options: eeproms, trace, "),
    ("@pytest.mark.orfa_robot(slaves=[], firmware_of_slaves=1)", "orfa_sim_robot",
     "orfa_robot: no SimBoard option firmware_of_slaves (options: eeproms, "),
    ("@pytest.mark.orfa_board(adc={9: 100})", "orfa_sim_board",
     "orfa: orfa-sim exited with 2 before its link appeared"),
    ("@pytest.mark.orfa_robot(slaves=[('m128s',)])", "orfa_sim_robot",
     "orfa_robot: slave ('m128s',) is not (board, addr) or (board, addr, elf)"),
    ("@pytest.mark.orfa_robot(slaves=[('m64', 0x10)])", "orfa_sim_robot",
     "orfa_robot slave: board 'm64' is not one of %s" % ", ".join(BOARDS)),
    ("@pytest.mark.orfa_robot(gateway='m8')", "orfa_sim_robot",
     "orfa_robot gateway: board 'm8' is not one of %s" % ", ".join(BOARDS)),
    ("@pytest.mark.orfa_robot('m32d')", "orfa_sim_robot",
     "orfa_robot takes keywords (gateway=, slaves=, SimBoard options), not ('m32d',)"),
])
def test_bad_marker_fails_the_test_with_one_line(tmp_path, decorator, fixture, message):
    text = "import pytest\n\n%s\ndef test_x(%s):\n    pass\n" % (decorator, fixture)
    status, out = user_pytest(tmp_path, text)
    assert status == 1 and summary(out) == {"error": 1}, out
    assert message in out, out
    assert "Traceback" not in out and "pytest_plugin.py" not in out, out


def test_missing_simulator_fails_with_the_hint(tmp_path):
    text = "def test_x(orfa_sim_board):\n    pass\n"
    status, out = user_pytest(tmp_path, text, env={"ORFA_SIM": str(tmp_path / "no-sim")})
    assert status == 1 and summary(out) == {"error": 1}, out
    assert "orfa: %s is missing: ORFA_SIM=%s set" % (tmp_path / "no-sim", tmp_path / "no-sim") in out, out


def test_firmware_directory_setting(tmp_path):
    """ORFA_FIRMWARE: a directory laid out like build/; the fixtures run its
    ELFs, and one missing there is an error (no fall-back)."""
    fw = tmp_path / "fw"
    (fw / "m32d-gate").mkdir(parents=True)
    shutil.copy(str(firmware_path("m32d")), str(fw / "m32d-gate" / "orfa.elf"))
    text = ("def test_x(orfa_sim_board):\n"
            "    with orfa_sim_board.gateway(timeout=5) as gw:\n"
            "        assert gw.request('V') == 'V1.1'\n"
            "    print('ELF', orfa_sim_board.firmware)\n")
    status, out = user_pytest(tmp_path, text, "-s", env={"ORFA_FIRMWARE": str(fw)})
    assert status == 0, out
    assert "ELF %s" % (fw / "m32d-gate" / "orfa.elf") in out, out
    status, out = user_pytest(tmp_path, text, "--orfa-board", "m128s",
                              env={"ORFA_FIRMWARE": str(fw)})
    assert status == 1 and summary(out) == {"error": 1}, out
    assert "orfa: %s is missing: ORFA_FIRMWARE=%s set" % (
        fw / "m128s-gate" / "orfa.elf", fw) in out, out


def test_a_simulator_that_did_not_end_well_is_reported(tmp_path):
    """A simulator that dies during the test (here killed; a crashed
    firmware ends it with 1) is an error at teardown, with its status."""
    text = ("import signal\n\n"
            "def test_x(orfa_sim_board):\n"
            "    orfa_sim_board.proc.send_signal(signal.SIGKILL)\n"
            "    orfa_sim_board.proc.wait()\n")
    status, out = user_pytest(tmp_path, text)
    assert status == 1 and summary(out) == {"passed": 1, "error": 1}, out
    assert "orfa: orfa-sim exited with -9: " in out, out
