"""The Russian quick start's sample sessions (docs/ru/README.md,
docs/ru/protocol.md) replayed against the boards they name: every
`orfa> REQUEST` line and the reply under it, exactly.

A page marks each session with the board it runs on, in an HTML comment
that Markdown does not show:

    <!-- sim: m32d eeprom=A0 slave=m128s:10 slave=m32d:12 -->

(the gateway's board, then EEPROMs and slave boards at 8-bit hex
addresses). The sessions of one page with the same board are replayed in
page order on one simulated board, so a later one sees what an earlier one
wrote."""

import re
from pathlib import Path
from typing import Dict, List, Tuple

import pytest

from conftest import require_builds, require_slave, running
from orfa.sim import SimBoard
from test_readme import sessions as readme_sessions

ROOT = Path(__file__).resolve().parents[2]
PAGES = ("docs/ru/README.md", "docs/ru/protocol.md")

SETUP = re.compile(r"<!-- sim: (.*?) -->$")
PROMPT = re.compile(r"    orfa> (.*)$")

Pair = Tuple[str, str]


def page_sessions(text: str) -> List[Tuple[str, List[Pair]]]:
    """[(setup, [(request, reply), ...])] of a page, one per setup comment."""
    out: List[Tuple[str, List[Pair]]] = []
    lines = text.splitlines()
    for i, line in enumerate(lines):
        m = SETUP.match(line.strip())
        if m:
            out.append((m.group(1).strip(), []))
            continue
        m = PROMPT.match(line)
        if m:
            assert out, "a session before any <!-- sim: ... --> comment: %r" % line
            reply = lines[i + 1] if i + 1 < len(lines) else ""
            assert reply.startswith("    ") and not PROMPT.match(reply), \
                "no reply under %r" % line
            out[-1][1].append((m.group(1), reply[4:]))
    return out


def by_setup(page: str) -> Dict[str, List[Pair]]:
    """The page's sessions joined per setup, in page order."""
    out: Dict[str, List[Pair]] = {}
    for setup, pairs in page_sessions((ROOT / page).read_text()):
        out.setdefault(setup, []).extend(pairs)
    return out


def parse_setup(setup: str) -> dict:
    """`m32d eeprom=A0 slave=m128s:10` as SimBoard's arguments."""
    words = setup.split()
    board, eeproms, slaves = words[0], [], []
    for word in words[1:]:
        key, _, value = word.partition("=")
        if key == "eeprom":
            eeproms.append(int(value, 16))
        elif key == "slave":
            kind, _, addr = value.partition(":")
            slaves.append((kind, int(addr, 16)))
        else:
            raise ValueError("unknown setup word %r in %r" % (word, setup))
    return {"board": board, "eeproms": tuple(eeproms), "slaves": slaves}


CASES = [(page, setup) for page in PAGES for setup in by_setup(page)]


def test_pages_have_sessions():
    counts = {page: sum(len(p) for p in by_setup(page).values()) for page in PAGES}
    assert counts["docs/ru/README.md"] >= 8
    assert counts["docs/ru/protocol.md"] >= 40
    for page in PAGES:
        for setup, pairs in page_sessions((ROOT / page).read_text()):
            assert pairs, "%s: <!-- sim: %s --> with no session under it" % (page, setup)


def test_the_demo_session_is_the_readmes():
    """docs/ru/README.md shows the same first session as README.md."""
    ru = page_sessions((ROOT / "docs/ru/README.md").read_text())
    assert ru[0] == ("m32d eeprom=A0", readme_sessions()["Two commands on a fresh machine"])


def test_the_parser_reads_setups_and_pairs():
    text = ("<!-- sim: m32d eeprom=A0 slave=m128s:10 -->\n\n"
            "    orfa> V\n    V1.1\n    orfa> S A2 P\n    ERROR 06\n")
    assert page_sessions(text) == [("m32d eeprom=A0 slave=m128s:10",
                                    [("V", "V1.1"), ("S A2 P", "ERROR 06")])]
    assert parse_setup("m32d eeprom=A0 slave=m128s:10") == {
        "board": "m32d", "eeproms": (0xA0,), "slaves": [("m128s", 0x10)]}
    with pytest.raises(ValueError):
        parse_setup("m32d eprom=A0")
    with pytest.raises(AssertionError):
        page_sessions("    orfa> V\n    V1.1\n")          # no board named


@pytest.mark.parametrize("page, setup", CASES, ids=["%s: %s" % c for c in CASES])
def test_session_replays(page, setup):
    want = by_setup(page)[setup]
    args = parse_setup(setup)
    require_builds([args["board"]])
    slaves = [(kind, addr, require_slave(kind, addr)) for kind, addr in args["slaves"]]
    with running(SimBoard(args["board"], eeproms=args["eeproms"], trace=True,
                          slaves=slaves)) as bench:
        got = [(req, bench.gw.request(req)) for req, _ in want]
    assert got == want
