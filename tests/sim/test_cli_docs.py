"""docs/cli.md's and docs/ru/cli.md's sample runs that start their own board
(`$ orfa --sim ...`) replayed: what the page shows is what the command prints."""

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import require_builds

ROOT = Path(__file__).resolve().parents[2]
PAGES = ("docs/cli.md", "docs/ru/cli.md")


def sample_runs(page):
    """[(command line, expected output)] of every indented `$ orfa --sim` run."""
    runs = []
    lines = (ROOT / page).read_text().splitlines()
    for i, line in enumerate(lines):
        m = re.match(r"    \$ (orfa --sim .*)$", line)
        if m is None:
            continue
        out = []
        for follow in lines[i + 1:]:
            if not follow.startswith("    ") or follow.startswith("    $ "):
                break
            out.append(follow[4:])
        runs.append((m.group(1), "\n".join(out)))
    return runs


RUNS = [(page, c, e) for page in PAGES for c, e in sample_runs(page)]


@pytest.mark.parametrize("page", PAGES)
def test_the_page_has_samples(page):
    assert len(sample_runs(page)) >= 8


@pytest.mark.parametrize("page, command, expected", RUNS,
                         ids=["%s: %s" % (p, c) for p, c, _ in RUNS])
def test_sample_run(page, command, expected):
    require_builds()
    argv = shlex.split(command)[1:]
    result = subprocess.run([sys.executable, "-m", "orfa"] + argv, capture_output=True,
                            text=True, timeout=60, cwd=ROOT,
                            env=dict(os.environ, PYTHONPATH=str(ROOT / "host")))
    assert (result.stdout + result.stderr).rstrip("\n") == expected
