"""The board maps are the one source of truth of the host side: generated
from the firmware's C definitions, read by Python, the tests, the benchmark
and the docs. These tests fail when any of them drifts."""

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from orfa import boardmap, boards
from orfa import protocol as p
from orfa.errors import Status

ROOT = Path(__file__).resolve().parents[2]
MAPS = ROOT / "host" / "orfa" / "maps"


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """The maps as `make map` writes them today, into a temporary folder."""
    out = tmp_path_factory.mktemp("maps")
    r = subprocess.run(["make", "--no-print-directory", "map", "MAP_OUT=%s" % out],
                       cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    return out


@pytest.mark.parametrize("board", boardmap.BOARDS)
def test_committed_map_is_what_the_c_gives(board, generated):
    fresh = (generated / ("%s.json" % board)).read_text()
    committed = (MAPS / ("%s.json" % board)).read_text()
    assert committed == fresh, "host/orfa/maps/%s.json is stale: run `make map`" % board


def test_generated_docs_are_current():
    """Both languages: docs/board-*.md and docs/ru/board-*.md."""
    r = subprocess.run([sys.executable, str(ROOT / "tools" / "docgen.py"), "--check"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr


@pytest.fixture
def docgen(monkeypatch):
    """tools/docgen.py as a module (its Russian texts in docgen.ru)."""
    monkeypatch.syspath_prepend(str(ROOT / "tools"))
    import docgen as module
    return module


def test_docgen_writes_both_languages(docgen):
    pages = docgen.pages()
    names = sorted(str(p.relative_to(ROOT)) for p in pages)
    assert names == ["docs/board-m128s.md", "docs/board-m32d.md",
                     "docs/ru/board-m128s.md", "docs/ru/board-m32d.md",
                     "docs/ru/protocol.md"]
    ru = pages[ROOT / "docs" / "ru" / "board-m32d.md"]
    assert "## Значения регистра статуса" in ru
    for c in boardmap.STATUS.values():
        assert "| `%02X` | %s | %s |" % (c.code, c.name, docgen.ru.STATUS[c.name]) in ru


def test_docgen_gives_both_languages_the_same_sections(docgen):
    """One generator: each page has the same headings and table rows, in its words."""
    m = boardmap.load("m128s")
    en, ru = docgen.page("m128s", docgen.en), docgen.page("m128s", docgen.ru)
    assert en.count("\n## ") == ru.count("\n## ") == 6
    assert en.count("\n|") == ru.count("\n|")
    assert en.count("\n* ") == ru.count("\n* ") == len({p.function for p in m.pins})
    assert "## Reset causes (the sys driver's RESET register)" in en
    for name, bit in m.reset_causes.items():
        assert "| `%02X` | %s | %s |" % (bit, name, docgen.en.RESET_CAUSES[name]) in en
        assert "| `%02X` | %s | %s |" % (bit, name, docgen.ru.RESET_CAUSES[name]) in ru
    assert "* CLKn: clock input of CD4017 counter n" in en
    for c in boardmap.ERRORS.values():
        assert "| `ERROR %02X` | %s | %s |" % (c.code, c.name, c.text) in en


def test_docgen_fills_the_error_table_of_the_russian_protocol_page(docgen, tmp_path):
    text = (ROOT / "docs" / "ru" / "protocol.md").read_text()
    assert docgen.fill_errors(text, docgen.ru) == text
    stale = text.replace("| `ERROR 05` | NO_P |", "| `ERROR 05` | OLD |")
    assert stale != text
    assert docgen.fill_errors(stale, docgen.ru) == text
    for c in boardmap.ERRORS.values():
        assert "| `ERROR %02X` | %s | %s |" % (c.code, c.name, docgen.ru.ERRORS[c.name]) in text
    with pytest.raises(docgen.MissingText, match="no block <!-- docgen:errors -->"):
        docgen.fill_errors("# no table here\n", docgen.ru)


def test_docgen_refuses_a_status_without_russian(docgen, monkeypatch, capsys):
    """A new status code in the map stops docgen until it has a Russian text."""
    codes = dict(boardmap.STATUS)
    codes[0x09] = boardmap.Code(0x09, "NEW_REASON", "something new")
    monkeypatch.setattr(boardmap, "STATUS", codes)
    monkeypatch.setattr(sys, "argv", ["docgen.py", "--check"])
    assert docgen.main() == 1
    err = capsys.readouterr().err
    assert err == ("docgen: m32d: no Russian text for status NEW_REASON "
                   "(add it to tools/docgen_ru.py)\n")


@pytest.mark.parametrize("table, key, label", [
    ("ERRORS", "NO_P", "error NO_P"),
    ("DRIVERS", "motor", "driver motor"),
    ("REGISTERS", ("servo", "SP"), "register servo/SP"),
    ("PIN_FUNCTIONS", "MOTOR_PWM", "pin function MOTOR_PWM"),
    ("RESET_CAUSES", "jtag", "reset cause jtag"),
])
def test_docgen_names_each_missing_russian_text(docgen, monkeypatch, table, key, label):
    texts = dict(getattr(docgen.ru, table))
    del texts[key]
    monkeypatch.setattr(docgen.ru, table, texts)
    assert docgen.missing(docgen.ru, boardmap.load("m32d")) == [label]
    with pytest.raises(docgen.MissingText, match="no Russian text for %s " % label):
        docgen.page("m32d", docgen.ru)
    if table == "ERRORS":
        with pytest.raises(docgen.MissingText, match="^protocol: no Russian text for error NO_P "):
            docgen.fill_errors((ROOT / "docs" / "ru" / "protocol.md").read_text(), docgen.ru)


def test_docgen_refuses_a_name_without_english(docgen, monkeypatch):
    """The English word set is checked the same way, naming its own file."""
    texts = dict(docgen.en.PIN_FUNCTIONS)
    del texts["SERVO_RST"]
    monkeypatch.setattr(docgen.en, "PIN_FUNCTIONS", texts)
    assert docgen.missing(docgen.en, boardmap.load("m32d")) == []
    with pytest.raises(docgen.MissingText) as e:
        docgen.page("m128s", docgen.en)
    assert str(e.value) == ("m128s: no English text for pin function SERVO_RST "
                            "(add it to tools/docgen_en.py)")


def test_mapgen_refuses_a_driver_whose_names_do_not_match_its_registers(tmp_path):
    """A driver that names fewer registers than it has stops `make map`."""
    src = (ROOT / "tools" / "mapgen.c").read_text()
    bad = tmp_path / "mapgen.c"
    bad.write_text(src.replace("int main(void)\n{",
                               "#undef DRV_adc_REGS\n#define DRV_adc_REGS(X) X(\"RC\", 0)\n"
                               "int main(void)\n{"))
    exe = tmp_path / "mapgen"
    cc = subprocess.run(["gcc", "-std=c99", "-I%s" % ROOT, "-I%s" % (ROOT / "boards" / "m32d"),
                         "-DORFA_DRIVER_LIST=X(gpio) X(adc)", '-DMAP_AVRDUDE_PART="m32"',
                         '-DMAP_FUSES="lfuse:0xff"', str(bad), "-o", str(exe)],
                        capture_output=True, text=True)
    assert cc.returncode == 0, cc.stderr
    r = subprocess.run([str(exe)], capture_output=True, text=True)
    assert r.returncode != 0
    assert "driver adc has 2 registers but names 1" in r.stderr


@pytest.mark.parametrize("board", boardmap.BOARDS)
def test_map_is_consistent(board):
    m = boardmap.load(board)
    start = 0
    for drv in m.drivers:                       # contiguous from 00, as regmap.c
        assert drv.start == start, drv
        assert len(drv.registers) == drv.count
        start += drv.count
    assert m.drivers[0].name == "intro" and m.drivers[-1].name == "sys"
    assert len(m.gpio_ports) * 2 == m.driver("gpio").count
    raw = json.loads((MAPS / ("%s.json" % board)).read_text())
    assert raw["board"] == board and raw["schema"] == 1


def c_codes(header: str, macro: str):
    """{code: name} of an X-macro list in the C (`X(NAME, 0x05, "text")`)."""
    text = (ROOT / header).read_text()
    body = text.split("#define %s(X)" % macro, 1)[1].split("\n\n", 1)[0]
    return {int(code, 16): name
            for name, code in re.findall(r"X\((\w+), (0x[0-9A-Fa-f]+),", body)}


def test_python_codes_have_the_c_names():
    """Names and numbers, straight from the C headers: the protocol's errors
    (serialgate/sg_parse.h) and the status register's codes
    (firmware/regmap.h)."""
    errors = c_codes("serialgate/sg_parse.h", "SG_ERR_LIST")
    assert errors == {1: "INTERNAL", 2: "COMMAND", 3: "HEX", 4: "DATA", 5: "NO_P",
                      6: "ADDR_NACK", 7: "DATA_NACK"}
    assert {int(c): c.name for c in p.ErrorCode} == errors
    assert {int(c): c.name for c in Status} == c_codes("firmware/regmap.h", "REG_STATUS_LIST")
    # each ERROR reply's class stands for the code of that name
    assert {cls.__name__: cls.code.name for cls in p.ERRORS_BY_CODE.values()} == {
        "InternalError": "INTERNAL", "UnknownCommandError": "COMMAND", "HexError": "HEX",
        "DataError": "DATA", "IncompleteError": "NO_P", "AddressNackError": "ADDR_NACK",
        "DataNackError": "DATA_NACK"}
    assert sorted(p.ERRORS_BY_CODE) == sorted(errors)
    assert p.ErrorCode.NO_P.text == "the line ended before the P of an I2C request"


def test_python_constants_follow_the_map():
    m = boardmap.load("m32d")
    for board in boardmap.BOARDS:
        bm = boardmap.load(board)
        assert bm.limits["request_chars"] == p.MAX_REQUEST_CHARS
        assert bm.limits["reply_chars"] == p.MAX_REPLY_CHARS
        assert bm.f_cpu == p.F_CPU
        assert bm.local_address == p.DEFAULT_LOCAL_ADDRESS
        assert boards.BOARD_UIDS[board] == bm.uids
        assert boards.SYS_REGISTER[board] == bm.reg("sys", "RESET")
    assert boards.FAILSAFE_MAX_MS == m.limits["failsafe_max_ms"] == 18000
    assert boards.RESET_CAUSES == {"power": 1, "external": 2, "brownout": 4,
                                   "watchdog": 8, "jtag": 16}


def test_lookups():
    m = boardmap.load("m32d")
    assert m.reg("servo", "SP") == 0x13 and boardmap.load("m128s").reg("servo", "sp") == 0x0B
    with pytest.raises(KeyError, match="no driver 'motor'"):
        boardmap.load("m128s").driver("motor")
    with pytest.raises(KeyError, match="no register 'XX'"):
        m.reg("servo", "XX")
    with pytest.raises(ValueError, match="no board"):
        boardmap.load("m64")
    assert boardmap.by_uids(m.uids) is m
    assert boardmap.by_uids([0x0000, 0x0020, 0x0002]) is m      # drivers left out
    assert boardmap.by_uids([0x0000, 0x0021, 0x0030, 0x0002]).board == "m128s"
    assert boardmap.by_uids([0x0000, 0x1234]) is None
    assert boardmap.STATUS[3].name == "PIN_BUSY"
