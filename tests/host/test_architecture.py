"""docs/architecture.md stays true: every file, folder and function it names
exists in the tree (a function: defined in a C or Python source file)."""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "architecture.md"
SOURCE_SUFFIXES = (".c", ".h", ".py")


def tracked():
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:                       # not a checkout: walk the tree
        return [str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_file()]
    return out.stdout.split()


FILES = tracked()
TOKENS = re.findall(r"`([^`]+)`", DOC.read_text())


def paths():
    """Backticked tokens that name a file or folder."""
    out = set()
    for tok in TOKENS:
        if "<" in tok or " " in tok or "(" in tok:
            continue
        if "/" in tok or tok.endswith((".c", ".h", ".py", ".md", ".json", ".mk")):
            out.add(tok)
    return sorted(out)


def functions():
    """Backticked `name()` and `ISR(VECTOR)` tokens."""
    out = set()
    for tok in TOKENS:
        if re.fullmatch(r"[A-Za-z_]\w*\(\)", tok) or re.fullmatch(r"ISR\(\w+\)", tok):
            out.add(tok)
    return sorted(out)


def test_the_doc_names_things():
    assert len(paths()) > 30 and len(functions()) > 25


@pytest.mark.parametrize("name", paths())
def test_every_named_path_exists(name):
    if "*" in name:
        assert list(ROOT.glob(name)), name
    elif "/" in name:
        assert (ROOT / name.rstrip("/")).exists(), name
    else:                                          # a bare file name: somewhere in the tree
        assert any(f == name or f.endswith("/" + name) for f in FILES), name


def _sources():
    for f in FILES:
        if f.endswith(SOURCE_SUFFIXES) and not f.startswith("tests/"):
            yield f, (ROOT / f).read_text(errors="replace")


SOURCES = list(_sources())


@pytest.mark.parametrize("name", functions())
def test_every_named_function_is_defined(name):
    if name.startswith("ISR("):
        pattern = re.compile(r"^ISR\(%s\b" % re.escape(name[4:-1]), re.M)
    else:
        fn = re.escape(name[:-2])
        # C: a definition starts a line (type, name, parenthesis); Python: def
        pattern = re.compile(r"^(?:[A-Za-z_][\w \*]*[\s\*])?%s\([^;]*$|^\s*def %s\(" % (fn, fn),
                             re.M)
    where = [f for f, text in SOURCES if pattern.search(text)]
    assert where, "%s is defined nowhere" % name


#: The firmware's C folders (docs/architecture.md, Folders).
FIRMWARE_DIRS = ("boards/", "firmware/", "drivers/", "serialgate/", "i2c_slave/")
EEPROM = re.compile(r"\bEE(DR|AR[LH]?|CR)\b|eeprom_")


def test_the_eeprom_is_the_serial_interrupts_alone():
    """The receive and transmit interrupts keep SREG in EEDR
    (firmware/uart.c, ISR_KEEP): no other firmware file touches the
    EEPROM's registers or avr-libc's EEPROM functions."""
    users = sorted(f for f in FILES if f.startswith(FIRMWARE_DIRS) and f.endswith((".c", ".h"))
                   and EEPROM.search((ROOT / f).read_text(errors="replace")))
    assert users == ["firmware/uart.c"]
