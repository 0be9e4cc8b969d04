"""orfa.locate: the order in which the simulator and the ELFs are looked up
(ORFA_SIM / ORFA_FIRMWARE, the installed package's copies, the work tree's
build/), and what the hint says in each case."""

import os
from pathlib import Path

import pytest

from orfa import locate, sim

BUILD = locate.REPO_ROOT / "build"


@pytest.fixture(autouse=True)
def no_settings(monkeypatch):
    monkeypatch.delenv("ORFA_SIM", raising=False)
    monkeypatch.delenv("ORFA_FIRMWARE", raising=False)


def touch(path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"\x7fELF")
    return path


@pytest.fixture
def package(tmp_path, monkeypatch):
    """Pretend the package carries copies (as installed) in tmp_path/pkg."""
    pkg = tmp_path / "pkg"
    monkeypatch.setattr(locate, "PACKAGE_SIM", pkg / "_sim" / "orfa-sim")
    monkeypatch.setattr(locate, "PACKAGE_FIRMWARE", pkg / "_firmware")
    return pkg


def test_work_tree_uses_build():
    assert locate.in_work_tree()
    assert locate.sim_path() == BUILD / "sim" / "orfa-sim"
    assert locate.firmware_path("m32d", "slave") == BUILD / "m32d-slave" / "orfa.elf"
    assert "run `make all-boards sim` in %s" % locate.REPO_ROOT in locate.build_hint()


def test_sim_module_gives_the_same_paths():
    assert sim.sim_path() == locate.sim_path()
    assert sim.firmware_path("m128s") == locate.firmware_path("m128s")
    assert sim.slave_firmware_path("m32d", 0x12) == locate.slave_firmware_path("m32d", 0x12)


def test_settings_come_first_and_are_final(tmp_path, monkeypatch, package):
    touch(package / "_sim" / "orfa-sim")
    touch(package / "_firmware" / "m32d-gate" / "orfa.elf")
    monkeypatch.setenv("ORFA_SIM", str(tmp_path / "my-sim"))
    monkeypatch.setenv("ORFA_FIRMWARE", str(tmp_path / "fw"))
    # not there, and still the answer: no fall-back behind a setting
    assert locate.sim_path() == tmp_path / "my-sim"
    assert locate.firmware_path("m32d") == tmp_path / "fw" / "m32d-gate" / "orfa.elf"
    assert locate.slave_firmware_path("m128s", 0x10) == tmp_path / "fw" / "m128s-slave" / "orfa.elf"
    assert locate.missing_builds(["m32d"]) == [tmp_path / "my-sim",
                                               tmp_path / "fw" / "m32d-gate" / "orfa.elf"]
    assert locate.build_hint() == (
        "ORFA_SIM=%s and ORFA_FIRMWARE=%s set (ORFA_SIM names an orfa-sim, ORFA_FIRMWARE a"
        " directory laid out like the repository's build/; unset to use the installed copies)"
        % (tmp_path / "my-sim", tmp_path / "fw"))


def test_firmware_setting_is_laid_out_like_build(tmp_path, monkeypatch):
    fw = tmp_path / "fw"
    robot = touch(fw / "robot" / "m128s-0x14" / "orfa.elf")
    slave = touch(fw / "m128s-slave" / "orfa.elf")
    monkeypatch.setenv("ORFA_FIRMWARE", str(fw))
    assert locate.slave_firmware_path("m128s", 0x14) == robot
    assert locate.slave_firmware_path("m128s", 0x16) == slave     # no robot build there
    assert locate.sim_path() == BUILD / "sim" / "orfa-sim"         # ORFA_SIM unset


def test_package_copies_before_the_work_tree(package):
    sim_copy = touch(package / "_sim" / "orfa-sim")
    gate = touch(package / "_firmware" / "m128s-gate" / "orfa.elf")
    assert locate.sim_path() == sim_copy
    assert locate.firmware_path("m128s") == gate
    # what the package lacks comes from the work tree's build/
    assert locate.firmware_path("m32d") == BUILD / "m32d-gate" / "orfa.elf"


def test_installed_hints(package, monkeypatch):
    monkeypatch.setattr(locate, "in_work_tree", lambda: False)
    assert locate.sim_path() == package / "_sim" / "orfa-sim"
    assert locate.firmware_path("m32d") == package / "_firmware" / "m32d-gate" / "orfa.elf"
    assert locate.build_hint().startswith(
        "this orfa was installed without the simulator (ORFA_SKIP_BUILD=1)")
    touch(package / "_sim" / "orfa-sim")
    assert locate.build_hint() == (
        "not part of the installed orfa (it has the builds of `make all-boards gate-rates robot sim`):"
        " give the ELF's path, or set ORFA_FIRMWARE")


def test_a_gateway_for_a_rate_is_made_in_the_work_tree():
    """The default rate is the default build; another is made (or found up
    to date) in build/<board>-gate-<rate>/; one make refuses is a one-line
    ValueError with make's reason."""
    assert locate.gateway_firmware("m32d", 115200) == locate.firmware_path("m32d")
    elf = locate.gateway_firmware("m128s", 230400)
    assert elf == BUILD / "m128s-gate-230400" / "orfa.elf" and elf.is_file()
    assert locate.gateway_firmware("m128s", "auto") == BUILD / "m128s-gate-auto" / "orfa.elf"
    with pytest.raises(ValueError) as exc:
        locate.gateway_firmware("m32d", 921600)
    assert str(exc.value).startswith("no m32d gateway at 921600 baud: BAUD=921600 is refused: ")
    assert "\n" not in str(exc.value) and "Stop" not in str(exc.value)


def test_two_programs_asking_for_one_build_at_once_both_get_it():
    """Two makes of one new build directory at once (two `orfa sim --baud R`
    started together) wrote its files together: one failed on the other's
    half-written configuration. make_gateway takes them one at a time."""
    import shutil
    from concurrent.futures import ThreadPoolExecutor
    build = "build/test-locate-%d" % os.getpid()
    try:
        with ThreadPoolExecutor(2) as pool:
            elfs = list(pool.map(lambda _: locate.make_gateway("m32d", 230400, build), range(2)))
        assert elfs == [locate.REPO_ROOT / build / "orfa.elf"] * 2 and elfs[0].is_file()
    finally:
        shutil.rmtree(locate.REPO_ROOT / build, ignore_errors=True)


def test_a_gateway_for_a_rate_outside_the_work_tree(package, monkeypatch, tmp_path):
    monkeypatch.setattr(locate, "in_work_tree", lambda: False)
    gate = touch(package / "_firmware" / "m32d-gate-460800" / "orfa.elf")
    assert locate.gateway_firmware("m32d", 460800) == gate
    with pytest.raises(ValueError) as exc:
        locate.gateway_firmware("m32d", 57600)
    assert str(exc.value) == (
        "no m32d gateway at 57600 baud: %s is not there (make BOARD=m32d MODE=gate BAUD=57600"
        " BUILD=build/m32d-gate-57600 in the source tree, then point ORFA_FIRMWARE at its"
        " build/)" % (package / "_firmware" / "m32d-gate-57600" / "orfa.elf"))
    # a setting is final, in the work tree too: nothing is made there
    monkeypatch.setattr(locate, "in_work_tree", lambda: True)
    monkeypatch.setenv("ORFA_FIRMWARE", str(tmp_path / "fw"))
    with pytest.raises(ValueError, match="fw/m32d-gate-230400/orfa.elf is not there"):
        locate.gateway_firmware("m32d", 230400)


def test_simboard_names_the_missing_file_and_the_setting(tmp_path, monkeypatch):
    monkeypatch.setenv("ORFA_SIM", str(tmp_path / "none"))
    with pytest.raises(sim.SimError) as exc:
        sim.SimBoard("m32d").start()
    assert str(exc.value).startswith("%s is missing: ORFA_SIM=%s set (" % (
        tmp_path / "none", tmp_path / "none"))


def test_simboard_says_when_the_simulator_cannot_run(tmp_path, monkeypatch):
    not_a_program = tmp_path / "orfa-sim"
    not_a_program.write_text("just text\n")          # not executable
    monkeypatch.setenv("ORFA_SIM", str(not_a_program))
    board = sim.SimBoard("m32d", firmware=__file__)
    with pytest.raises(sim.SimError) as exc:
        board.start()
    assert str(exc.value).startswith("cannot run %s: Permission denied; ORFA_SIM=" % not_a_program)
    assert board.proc is None and board.dir is None
