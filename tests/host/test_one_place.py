"""Each fact in one place, the rest read from it: the boards' clock
(board.h). These tests fail when a copy appears again or when a reader of
the fact stops agreeing with it."""

import subprocess
from pathlib import Path

import pytest

from orfa import boardmap

ROOT = Path(__file__).resolve().parents[2]

#: Where the clock's number may stand: its one place, the maps generated
#: from it, and prose.
CLOCK_PLACES = ("boards/*/board.h", "host/orfa/maps/*.json", "docs/*.md", "README.md")


def tracked_files():
    r = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip("not a git work tree: %s" % r.stderr.strip())
    return [Path(name) for name in r.stdout.splitlines()]


def test_the_clock_is_written_once():
    clock = str(boardmap.F_CPU)
    strays = []
    for path in tracked_files():
        if any(path.match(pattern) for pattern in CLOCK_PLACES):
            continue
        try:
            text = (ROOT / path).read_text()
        except (UnicodeDecodeError, FileNotFoundError):
            continue
        strays += ["%s:%d" % (path, n) for n, line in enumerate(text.splitlines(), 1)
                   if clock in line]
    assert strays == [], "the clock stands again outside board.h: %s" % ", ".join(strays)


def test_every_board_has_the_one_clock():
    assert {boardmap.load(b).f_cpu for b in boardmap.BOARDS} == {boardmap.F_CPU}


def test_maps_that_differ_in_a_shared_fact_are_an_error(monkeypatch):
    maps = {"m32d": {"f_cpu": 8000000}, "m128s": {"f_cpu": 16000000}}
    monkeypatch.setattr(boardmap, "_read", maps.__getitem__)
    with pytest.raises(ValueError, match="the board maps differ in 'f_cpu'"):
        boardmap._shared("f_cpu")
