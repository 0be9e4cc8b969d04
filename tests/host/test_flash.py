"""Flashing: `make flash`, `make fuses` and `orfa flash` run avrdude with the
documented command lines (a stand-in avrdude on PATH records them: Debian's
avrdude 7.1 has no dry-run programmer), and what they write to flash is the
ELF's .text and .data byte for byte."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

from flashcheck import Avrdude, elf_flash_image, elf_flash_sections, read_ihex  # noqa: E402

from orfa import boardmap, flash  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
BOARDS = ("m32d", "m128s")
MODES = ("gate", "slave")

# The command lines README.md and docs/flashing.md show (avrdude's part and
# the fuses of boards/<board>/board.mk).
PART = {"m32d": "m32", "m128s": "m128"}
FUSES = {"m32d": ["lfuse:w:0xff:m", "hfuse:w:0xd9:m"],
         "m128s": ["lfuse:w:0xff:m", "hfuse:w:0xd9:m", "efuse:w:0xff:m"]}

# (make variables, orfa options, programmer, port)
VARIANTS = [
    ([], [], "usbasp", None),
    (["PORT=/dev/ttyUSB0"], ["--port", "/dev/ttyUSB0"], "usbasp", "/dev/ttyUSB0"),
    (["PROGRAMMER=avrisp2", "PORT=usb"], ["--programmer", "avrisp2", "--port", "usb"],
     "avrisp2", "usb"),
]
VARIANT_IDS = ["defaults", "port", "programmer+port"]


def expected(board, programmer, port, *updates):
    argv = ["-c", programmer, "-p", PART[board]] + (["-P", port] if port else [])
    for u in updates:
        argv += ["-U", u]
    return argv


def fuse_updates(board):
    return FUSES[board]


@pytest.fixture
def avrdude(tmp_path):
    return Avrdude(tmp_path / "standin")


@pytest.fixture(scope="module")
def built():
    """The four builds of `make all-boards` (nothing to do when up to date)."""
    for board in BOARDS:
        for mode in MODES:
            r = subprocess.run(["make", "--no-print-directory", "BOARD=" + board,
                                "MODE=" + mode, "firmware"], cwd=ROOT,
                               capture_output=True, text=True, timeout=600)
            assert r.returncode == 0, r.stderr


def make(avrdude, *args, env=None):
    return subprocess.run(["make", "--no-print-directory"] + list(args), cwd=ROOT,
                          env=env or avrdude.env(), capture_output=True, text=True,
                          timeout=600)


def orfa(avrdude, *args, env=None, cwd=ROOT):
    env = dict(env or avrdude.env())
    env["PYTHONPATH"] = str(ROOT / "host")
    return subprocess.run([sys.executable, "-m", "orfa", "flash"] + list(args), cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=120)


def assert_hex_is_elf(hex_path, elf, tmp):
    """The Intel HEX holds exactly the ELF's .text and .data (at .data's load
    address, right after .text), nothing else."""
    sections = {name: (lma, size) for name, lma, size in elf_flash_sections(elf)}
    assert ".text" in sections and set(sections) <= {".text", ".data"}, sections
    text_lma, text_size = sections[".text"]
    data_lma, data_size = sections.get(".data", (text_size, 0))    # the M128-S gateway
    assert text_lma == 0 and data_lma == text_size                  # has no .data
    image = read_ihex(hex_path)
    assert sorted(image) == list(range(text_size + data_size))
    assert image == elf_flash_image(elf, tmp)


# --- make flash / make fuses ---------------------------------------------------

@pytest.mark.parametrize("variant", VARIANTS, ids=VARIANT_IDS)
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("board", BOARDS)
def test_make_flash_runs_avrdude_on_the_builds_hex(board, mode, variant, avrdude, built,
                                                    tmp_path):
    make_vars, _, programmer, port = variant
    r = make(avrdude, "flash", "BOARD=" + board, "MODE=" + mode, *make_vars)
    assert r.returncode == 0, r.stderr
    hex_rel = "build/%s-%s/orfa.hex" % (board, mode)
    want = expected(board, programmer, port, "flash:w:%s:i" % hex_rel)
    assert avrdude.calls() == [want]
    assert "avrdude " + " ".join(want) in r.stdout       # the command, shown
    assert "stand-in avrdude: done" in r.stdout          # avrdude's output, passed
    assert_hex_is_elf(avrdude.written()[0], ROOT / hex_rel.replace(".hex", ".elf"), tmp_path)


@pytest.mark.parametrize("variant", VARIANTS, ids=VARIANT_IDS)
@pytest.mark.parametrize("board", BOARDS)
def test_make_fuses_writes_the_boards_fuses(board, variant, avrdude):
    make_vars, _, programmer, port = variant
    r = make(avrdude, "fuses", "BOARD=" + board, *make_vars)
    assert r.returncode == 0, r.stderr
    assert avrdude.calls() == [expected(board, programmer, port, *fuse_updates(board))]
    assert avrdude.written() == []


def test_make_avrdude_variable_and_extra_flags(avrdude, built, tmp_path):
    env = avrdude.env()
    env["PATH"] = os.environ["PATH"]                     # not on PATH: named by AVRDUDE
    r = make(avrdude, "flash", "BOARD=m128s", "MODE=gate", "AVRDUDE=%s" % avrdude.path,
             "AVRDUDE_FLAGS=-B 10 -V", env=env)
    assert r.returncode == 0, r.stderr
    assert avrdude.calls() == [["-c", "usbasp", "-p", "m128", "-B", "10", "-V",
                                "-U", "flash:w:build/m128s-gate/orfa.hex:i"]]


def test_make_flash_builds_the_hex_first_with_the_builds_variables(avrdude, tmp_path):
    build = tmp_path / "b"
    r = make(avrdude, "flash", "BOARD=m32d", "MODE=slave", "ADDR=0x14", "BUILD=%s" % build)
    assert r.returncode == 0, r.stderr
    assert "avr-gcc" in r.stdout and "-DORFA_ADDR=0x14" in r.stdout
    assert avrdude.calls() == [expected("m32d", "usbasp", None,
                                        "flash:w:%s/orfa.hex:i" % build)]
    assert_hex_is_elf(avrdude.written()[0], build / "orfa.elf", tmp_path)


def test_make_without_avrdude_says_so(avrdude, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    make_exe = shutil.which("make")
    r = subprocess.run([make_exe, "--no-print-directory", "fuses"], cwd=ROOT,
                       env=dict(avrdude.env(), PATH=str(empty)), capture_output=True,
                       text=True, timeout=60)
    assert r.returncode != 0
    assert "avrdude not found: install avrdude (tools/setup.sh)" in r.stderr, r.stderr
    r = make(avrdude, "fuses", "AVRDUDE=/nowhere/avrdude")
    assert r.returncode != 0 and "/nowhere/avrdude not found" in r.stderr
    assert avrdude.calls() == []


def test_make_stops_when_avrdude_fails(avrdude, built):
    avrdude.fail_with(1)
    for target in ("flash", "fuses"):
        r = make(avrdude, target, "BOARD=m32d")
        assert r.returncode != 0
        assert "stand-in avrdude: failed" in r.stderr
    assert len(avrdude.calls()) == 2


# --- orfa flash ----------------------------------------------------------------

@pytest.mark.parametrize("variant", VARIANTS, ids=VARIANT_IDS)
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("board", BOARDS)
def test_orfa_flash_runs_what_make_flash_runs(board, mode, variant, avrdude, built,
                                              tmp_path):
    _, options, programmer, port = variant
    r = orfa(avrdude, "--board", board, "--mode", mode, *options)
    assert r.returncode == 0, r.stderr
    hex_rel = "build/%s-%s/orfa.hex" % (board, mode)
    assert avrdude.calls() == [expected(board, programmer, port, "flash:w:%s:i" % hex_rel)]
    assert "stand-in avrdude: done" in r.stdout
    assert_hex_is_elf(avrdude.written()[0], ROOT / hex_rel.replace(".hex", ".elf"), tmp_path)


@pytest.mark.parametrize("variant", VARIANTS, ids=VARIANT_IDS)
@pytest.mark.parametrize("board", BOARDS)
def test_orfa_flash_fuses_runs_what_make_fuses_runs(board, variant, avrdude):
    _, options, programmer, port = variant
    r = orfa(avrdude, "--board", board, "--fuses", *options)
    assert r.returncode == 0, r.stderr
    assert avrdude.calls() == [expected(board, programmer, port, *fuse_updates(board))]


def test_orfa_flash_outside_the_repository_names_the_hex_by_its_full_path(avrdude, built,
                                                                         tmp_path):
    r = orfa(avrdude, "--board", "m128s", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert avrdude.calls() == [expected("m128s", "usbasp", None, "flash:w:%s:i"
                                        % (ROOT / "build/m128s-gate/orfa.hex"))]


@pytest.mark.parametrize("board", BOARDS)
def test_orfa_flash_converts_an_elf_given_as_hex(board, avrdude, built, tmp_path):
    elf = ROOT / "build" / ("%s-gate" % board) / "orfa.elf"
    r = orfa(avrdude, "--board", board, "--hex", str(elf))
    assert r.returncode == 0, r.stderr
    (call,) = avrdude.calls()
    written = call[-1][len("flash:w:"):-len(":i")]
    assert call[:-1] == expected(board, "usbasp", None)[:] + ["-U"]
    assert written.endswith("/orfa.hex") and not Path(written).exists()   # temporary
    assert_hex_is_elf(avrdude.written()[0], elf, tmp_path)


def _run_in_process(monkeypatch, avrdude, firmware, *args):
    """orfa flash in this process, the firmware's ELF at `firmware(board, mode)`,
    as after `pip install .` (ELFs shipped, no .hex)."""
    monkeypatch.setenv("PATH", avrdude.env()["PATH"])
    monkeypatch.delenv("AVRDUDE", raising=False)
    monkeypatch.setattr(flash, "firmware_path", firmware)
    import argparse
    parser = argparse.ArgumentParser(prog="orfa")
    flash.add_parser(parser.add_subparsers(dest="command", required=True))
    ns = parser.parse_args(["flash"] + list(args))
    return ns.func(ns)


def test_orfa_flash_with_only_the_elf_converts_it(monkeypatch, avrdude, built, tmp_path,
                                                  capsys):
    shipped = tmp_path / "firmware" / "m32d-slave.elf"
    shipped.parent.mkdir()
    shutil.copyfile(ROOT / "build/m32d-slave/orfa.elf", shipped)
    rc = _run_in_process(monkeypatch, avrdude, lambda b, m: shipped, "--mode", "slave")
    assert rc == 0, capsys.readouterr().err
    assert len(avrdude.calls()) == 1
    assert_hex_is_elf(avrdude.written()[0], shipped, tmp_path)


def test_orfa_flash_converts_the_elf_when_the_hex_is_older(monkeypatch, avrdude, built,
                                                           tmp_path, capsys):
    elf = tmp_path / "m128s-gate" / "orfa.elf"
    elf.parent.mkdir()
    shutil.copyfile(ROOT / "build/m128s-gate/orfa.elf", elf)
    stale = elf.with_name("orfa.hex")
    stale.write_text(":00000001FF\n")
    os.utime(stale, (elf.stat().st_mtime - 10,) * 2)
    rc = _run_in_process(monkeypatch, avrdude, lambda b, m: elf, "--board", "m128s")
    assert rc == 0, capsys.readouterr().err
    assert_hex_is_elf(avrdude.written()[0], elf, tmp_path)
    os.utime(stale, (elf.stat().st_mtime + 10,) * 2)       # newer: used as it is
    rc = _run_in_process(monkeypatch, avrdude, lambda b, m: elf, "--board", "m128s")
    assert rc == 0
    assert avrdude.calls()[1][-1] == "flash:w:%s:i" % stale


def test_orfa_flash_without_firmware_says_how_to_build_it(monkeypatch, avrdude, tmp_path,
                                                         capsys):
    missing = tmp_path / "nothing" / "orfa.elf"
    rc = _run_in_process(monkeypatch, avrdude, lambda b, m: missing, "--mode", "slave")
    err = capsys.readouterr().err
    assert rc == 2
    assert err.startswith("orfa: no firmware for m32d slave: build it with"
                          " `make BOARD=m32d MODE=slave ADDR=0x10`"), err
    assert avrdude.calls() == []


def test_orfa_flash_dry_run_prints_the_command_only(avrdude, built):
    r = orfa(avrdude, "--dry-run")
    assert r.returncode == 0, r.stderr
    assert r.stdout == "avrdude -c usbasp -p m32 -U flash:w:build/m32d-gate/orfa.hex:i\n"
    r = orfa(avrdude, "--dry-run", "--board", "m128s", "--fuses", "--port", "/dev/tty USB")
    assert r.returncode == 0, r.stderr
    assert r.stdout == ("avrdude -c usbasp -p m128 -P '/dev/tty USB' -U lfuse:w:0xff:m"
                        " -U hfuse:w:0xd9:m -U efuse:w:0xff:m\n")
    assert avrdude.calls() == []


def test_orfa_flash_rate_writes_the_gateway_built_for_it(avrdude, built):
    """--rate picks build/<board>-gate-<rate>/ (made first in the source
    tree), the default rate the default build; a rate make refuses, a word
    that is no rate and a slave's mode are one line each, exit 2."""
    r = orfa(avrdude, "--rate", "460800", "--dry-run")
    assert (r.returncode, r.stderr) == (0, "")
    assert r.stdout == "avrdude -c usbasp -p m32 -U flash:w:build/m32d-gate-460800/orfa.hex:i\n"
    r = orfa(avrdude, "--board", "m128s", "--rate", "auto")
    assert r.returncode == 0, r.stderr
    assert avrdude.calls() == [expected("m128s", "usbasp", None,
                                        "flash:w:build/m128s-gate-auto/orfa.hex:i")]
    r = orfa(avrdude, "--rate", "115200", "--dry-run")
    assert r.stdout == "avrdude -c usbasp -p m32 -U flash:w:build/m32d-gate/orfa.hex:i\n"
    for args, err in [
            (["--rate", "921600"], "orfa: no m32d gateway at 921600 baud: BAUD=921600 is refused: "),
            (["--rate", "460800", "--mode", "slave"],
             "orfa: --rate picks the gateway built for that serial rate: it goes with --mode"
             " gate, not --mode slave"),
            (["--rate", "fast"], "orfa flash: error: argument --rate: 'fast' is not a serial"
                                 " rate (460800) or auto")]:
        r = orfa(avrdude, *args)
        assert r.returncode == 2 and r.stdout == "", args
        assert r.stderr.startswith(err) and len(r.stderr.splitlines()) == 1, r.stderr
    assert len(avrdude.calls()) == 1


def test_orfa_flash_without_avrdude_is_one_clear_line(avrdude, built, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    r = orfa(avrdude, env=dict(avrdude.env(), PATH=str(empty)))
    assert r.returncode == 2
    assert r.stderr == ("orfa: avrdude not found on PATH: install avrdude (tools/setup.sh,"
                        " or `apt install avrdude`) or give --avrdude PATH\n")
    r = orfa(avrdude, "--avrdude", "/nowhere/avrdude")
    assert r.returncode == 2
    assert r.stderr.startswith("orfa: /nowhere/avrdude not found: install avrdude")
    r = orfa(avrdude, "--fuses", env=dict(avrdude.env(), AVRDUDE=str(avrdude.path),
                                           PATH=str(empty)))
    assert r.returncode == 0, r.stderr                   # $AVRDUDE names it
    assert avrdude.calls() == [expected("m32d", "usbasp", None, *fuse_updates("m32d"))]


def test_orfa_flash_when_avrdude_fails(avrdude, built):
    avrdude.fail_with(3)
    r = orfa(avrdude, "--board", "m128s")
    assert r.returncode == 1
    assert r.stderr == "stand-in avrdude: failed\norfa: avrdude failed (exit status 3)\n"
    r = orfa(avrdude, "--fuses")
    assert r.returncode == 1 and "orfa: avrdude failed" in r.stderr


def test_orfa_flash_refuses_bad_input_before_avrdude(avrdude, built, tmp_path):
    text = tmp_path / "notes.txt"
    text.write_text("not firmware\n")
    x86 = tmp_path / "x86.elf"                # a 32-bit ELF header for the i386
    x86.write_bytes(b"\x7fELF\x01\x01\x01" + bytes(11) + b"\x03\x00" + bytes(32))
    cases = [
        (["--hex", str(tmp_path / "missing.hex")],
         "orfa: cannot read %s: No such file or directory\n" % (tmp_path / "missing.hex")),
        (["--hex", str(text)], "orfa: %s is neither Intel HEX nor an ELF file\n" % text),
        (["--hex", str(x86)], "orfa: %s: an ELF for machine 3, not the AVR (83)\n" % x86),
    ]
    # an ELF of the other board's MCU (its note says which: avr-libc's deviceinfo)
    for board, other in (("m32d", "m128s"), ("m128s", "m32d")):
        elf = ROOT / "build" / ("%s-gate" % other) / "orfa.elf"
        cases.append((["--board", board, "--hex", str(elf)],
                      "orfa: %s was built for the %s, not the %s's %s (--board)\n"
                      % (elf, boardmap.load(other).mcu, board, boardmap.load(board).mcu)))
    for args, message in cases:
        r = orfa(avrdude, *args)
        assert r.returncode == 2, (args, r.stderr)
        assert message in r.stderr and "Traceback" not in r.stderr
    for args, message in [(["--board", "m64"], "invalid choice: 'm64'"),
                          (["--mode", "master"], "invalid choice: 'master'"),
                          (["--fuses", "--hex", "x.hex"], "not allowed with argument")]:
        r = orfa(avrdude, *args)
        assert r.returncode == 2 and message in r.stderr, r.stderr
    assert avrdude.calls() == []


def test_argv_functions():
    assert flash.avrdude_argv("m32") == ["avrdude", "-c", "usbasp", "-p", "m32"]
    assert flash.avrdude_argv("m32", port="") == ["avrdude", "-c", "usbasp", "-p", "m32"]
    assert flash.avrdude_argv("m128", "stk500v2", "/dev/ttyACM0", "/opt/avrdude",
                              ["-B", "4"]) == ["/opt/avrdude", "-c", "stk500v2", "-p", "m128",
                                               "-P", "/dev/ttyACM0", "-B", "4"]
    assert flash.flash_argv("m128s", "a.hex")[1:] == expected("m128s", "usbasp", None,
                                                              "flash:w:a.hex:i")
    assert flash.fuses_argv("m32d", port="usb")[1:] == expected("m32d", "usbasp", "usb",
                                                                *fuse_updates("m32d"))
    with pytest.raises(flash.FlashError, match="no such board 'm64'"):
        flash.fuses_argv("m64")


def doc_examples(path):
    """(command words, avrdude argv) of each `make ...` line followed by a
    `# runs: avrdude ...` line, and of each `$ orfa flash ... --dry-run` line
    followed by its output, in a document."""
    lines = [line.strip() for line in path.read_text().splitlines()]
    pairs = []
    for line, after in zip(lines, lines[1:]):
        words = line.split("#")[0].split()
        if words[:1] == ["make"] and after.startswith("# runs: avrdude "):
            pairs.append((words, after.split()[3:]))
        elif words[:3] == ["$", "orfa", "flash"] and after.startswith("avrdude "):
            pairs.append((words[1:], after.split()[1:]))
    return pairs


@pytest.mark.parametrize("doc", ["README.md", "docs/flashing.md"])
def test_the_docs_command_lines_are_what_runs(doc, avrdude, built):
    examples = doc_examples(ROOT / doc)
    assert len(examples) >= 4, examples
    targets = set()
    for words, argv in examples:
        if words[0] == "make":
            r = make(avrdude, *words[1:])
            targets.add(words[1])
        else:
            r = orfa(avrdude, *[w for w in words[2:] if w != "--dry-run"])
        assert r.returncode == 0, (words, r.stderr)
        assert avrdude.calls()[-1] == argv, words
    assert {"flash", "fuses"} <= targets


# --- --addr: which slave build (issue 16) ---------------------------------------

def _fake_build(root, rel, addr=None):
    """An ELF and a newer .hex at root/rel (and make's flags file with ADDR)."""
    d = root / rel
    d.mkdir(parents=True)
    (d / "orfa.elf").write_bytes(b"\x7fELF")
    (d / "orfa.hex").write_text(":00000001FF\n")
    if addr is not None:
        (d / "flags").write_text("-mmcu=atmega128 -DORFA_ADDR=%s -DORFA_MODE_slave\n" % addr)
    return d


def test_orfa_flash_slave_addr_picks_the_build_that_answers_on_it(avrdude, tmp_path):
    """`--mode slave --addr 0x10` is the packaged slave build (built at 0x10);
    another address is the robot's build there, or how to build one."""
    fw = tmp_path / "fw"
    _fake_build(fw, "m128s-slave")                        # no flags: the package's copy
    _fake_build(fw, "robot/m128s-0x14", "0x14")
    env = dict(avrdude.env(), ORFA_FIRMWARE=str(fw))
    r = orfa(avrdude, "--board", "m128s", "--mode", "slave", "--addr", "0x10", "--dry-run",
             env=env)
    assert (r.returncode, r.stderr) == (0, "")
    assert r.stdout == ("avrdude -c usbasp -p m128 -U flash:w:%s:i\n"
                        % (fw / "m128s-slave" / "orfa.hex"))
    r = orfa(avrdude, "--board", "m128s", "--mode", "slave", "--addr", "0x14", "--dry-run",
             env=env)
    assert r.returncode == 0 and "robot/m128s-0x14/orfa.hex" in r.stdout, r.stderr
    r = orfa(avrdude, "--board", "m128s", "--mode", "slave", "--addr", "0x12", env=env)
    assert (r.returncode, r.stderr) == (
        2, "orfa: no m128s slave build at 0x12 (the packaged one answers on 0x10): build it"
           " with `make BOARD=m128s MODE=slave ADDR=0x12`, or give --hex FILE\n")
    # a work tree's build/<board>-slave built at another ADDR says so in its flags
    (fw / "m128s-slave" / "flags").write_text("-DORFA_ADDR=0x12 -DORFA_MODE_slave\n")
    r = orfa(avrdude, "--board", "m128s", "--mode", "slave", "--addr", "0x12", "--dry-run",
             env=env)
    assert r.returncode == 0 and "m128s-slave/orfa.hex" in r.stdout, r.stderr
    assert avrdude.calls() == []


@pytest.mark.parametrize("args, message", [
    (["--addr", "0x10"], "it goes with --mode slave, not --mode gate"),
    (["--mode", "slave", "--addr", "0x10", "--fuses"], "not --fuses"),
    (["--mode", "slave", "--addr", "0x11"], "--addr 0x11: a slave's 8-bit bus address is even"),
    (["--mode", "slave", "--addr", "0x100"], "--addr 0x100: a slave's 8-bit bus address"),
])
def test_orfa_flash_bad_addr_is_one_line(args, message, avrdude):
    r = orfa(avrdude, "--board", "m128s", "--dry-run", *args)
    assert r.returncode == 2 and r.stdout == "" and r.stderr.count("\n") == 1, r.stderr
    assert message in r.stderr


def test_orfa_flash_help_says_the_packaged_slave_builds_address(avrdude):
    r = orfa(avrdude, "--help")
    text = " ".join(r.stdout.split())
    assert "0x10 for the packaged build/<board>-slave" in text
    assert "--addr ADDR with --mode slave" in text
