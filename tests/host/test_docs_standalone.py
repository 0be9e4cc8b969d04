"""The repository stands alone: a user who clones it has only what is in it
(not the team's shared folder next to it), so no tracked file cites what lies
outside it, and every relative link of the
user docs (README.md, host/README.md, docs/**/*.md) reaches a file that the
repository holds."""

import re
import subprocess
from pathlib import Path
from typing import List

import pytest

ROOT = Path(__file__).resolve().parents[2]

#: What a clone does not have: the folder next to the repository and the
#: contract and simulator notes kept there (spelt in pieces, so that this
#: file does not name them itself).
OUTSIDE = ("../" + "shared", "SP" "EC.md", "SIMAVR" + "-NOTES")

#: The contract cited by its bare name ("... section 3", "...'s flow rule"): the
#: upper-case word alone, not spec_model.py nor an identifier that starts with it.
CONTRACT_WORD = re.compile(r"\b%s\b" % ("SP" "EC"))

#: Files whose bytes are data, not text (the fuzzers' seeds).
SKIP_DIRS = ("tests/fuzz/corpus/", ".git/", "build/")

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")


def tracked_files() -> List[Path]:
    """The repository's files: git's list in a checkout, else a walk."""
    r = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True)
    if r.returncode == 0 and r.stdout:
        names = [n for n in r.stdout.decode().split("\0") if n]
    else:
        names = [str(p.relative_to(ROOT)) for p in ROOT.rglob("*") if p.is_file()]
    return [ROOT / n for n in sorted(names)
            if not n.startswith(SKIP_DIRS) and (ROOT / n).is_file()]


def text_of(path: Path):
    """The file's text, or None for a binary file."""
    data = path.read_bytes()
    if b"\0" in data[:8192]:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def outside_mentions(text: str) -> List[str]:
    """`line: text` of every line that names something outside the repository."""
    return ["%d: %s" % (i, line.strip()) for i, line in enumerate(text.splitlines(), 1)
            if any(word in line for word in OUTSIDE) or CONTRACT_WORD.search(line)]


def doc_pages() -> List[Path]:
    pages = [ROOT / "README.md", ROOT / "host" / "README.md"]
    pages += sorted((ROOT / "docs").rglob("*.md"))
    return [p for p in pages if p.is_file()]


def broken_links(page: Path, root: Path = ROOT) -> List[str]:
    """Relative link targets of a Markdown page that name no file or folder
    inside `root`."""
    bad = []
    for target in LINK.findall(page.read_text()):
        if re.match(r"[a-z][a-z0-9+.-]*:", target, re.I) or target.startswith("#"):
            continue                    # http(s), mailto ...; an anchor on the page
        path = target.split("#", 1)[0]
        resolved = (page.parent / path).resolve()
        if not resolved.exists() or root.resolve() not in (resolved, *resolved.parents):
            bad.append(target)
    return bad


def test_the_walk_finds_the_repository():
    names = {str(p.relative_to(ROOT)) for p in tracked_files()}
    assert {"README.md", "docs/protocol.md", "Makefile", "host/orfa/protocol.py"} <= names
    assert not any(n.startswith("tests/fuzz/corpus/") for n in names)


def test_no_file_cites_what_a_clone_lacks():
    hits = []
    for path in tracked_files():
        text = text_of(path)
        if text is None:
            continue
        hits += ["%s:%s" % (path.relative_to(ROOT), h) for h in outside_mentions(text)]
    assert hits == []


#: Lines the check must flag (True) or let pass (False).
CITATIONS = [
    ("see %s/%s section 2" % OUTSIDE[:2], True),
    ("* %s: TWINT" % OUTSIDE[2], True),
    ("the contract (%s)" % OUTSIDE[1], True),
    ("as %s section 3 says" % ("SP" "EC"), True),
    ("(%s: 10 ms)" % ("SP" "EC"), True),
    ("%s's flow rule" % ("SP" "EC"), True),
    ("tests/sim/spec_model.py, the reference model", False),
    ("#define %s_LEN 4" % ("SP" "EC"), False),
    ("the Spec sheet", False),
    ("docs/simulator.md, \"What simavr 1.6 gets wrong\"", False),
]


@pytest.mark.parametrize("line, found", CITATIONS,
                         ids=["line%d" % i for i in range(len(CITATIONS))])
def test_the_check_sees_a_citation(line, found):
    assert bool(outside_mentions("x\n%s\n" % line)) is found


def test_every_doc_page_links_only_to_files_it_has():
    bad = {str(p.relative_to(ROOT)): broken_links(p) for p in doc_pages()}
    assert {page: links for page, links in bad.items() if links} == {}


def test_the_link_check_catches_a_broken_link(tmp_path):
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "protocol.md").write_text("# p\n")
    (tmp_path / "outside.md").write_text("# o\n")
    page = tmp_path / "docs" / "page.md"
    page.write_text("[ok](protocol.md#errors) [web](https://example.org/x.md) "
                    "![pic](missing.png) [gone](nowhere/page.md#a) [here](#top) "
                    "[up](../outside.md) [out](../../elsewhere.md)\n")
    assert broken_links(page, root=tmp_path) == [
        "missing.png", "nowhere/page.md#a", "../../elsewhere.md"]
