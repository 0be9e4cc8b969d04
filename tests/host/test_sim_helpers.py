"""sim.py parts that need no simulator: trace parsing, paths, errors."""

import pytest

from orfa import sim


def test_parse_trace_lines():
    text = ("841139 uart rx 56\n841997 uart tx 0A\n904293 twi start\n"
            "904980 twi addr A0 ack\n905000 twi read FF nack\n905121 twi stop\n"
            "999999 reset\n")
    assert sim.parse_trace(text) == [
        (841139, "uart rx", ("56",)), (841997, "uart tx", ("0A",)),
        (904293, "twi start", ()), (904980, "twi addr", ("A0", "ack")),
        (905000, "twi read", ("FF", "nack")), (905121, "twi stop", ()),
        (999999, "reset", ()),
    ]
    assert sim.parse_trace_line("1 twi stop").cycle == 1


@pytest.mark.parametrize("bad", ["", "uart rx 56", "x1 twi stop", "12"])
def test_bad_trace_lines(bad):
    with pytest.raises(ValueError):
        sim.parse_trace_line(bad)


def test_sent_lines_of_either_way():
    """The gateway's lines (CR LF ended) or the PC's (LF ended), at their
    first or last byte's cycle; bytes after the last end are no line."""
    text = "".join("%d uart %s %02X\n" % (10 * k, way, b) for k, (way, b) in enumerate(
        [("rx", 0x56), ("rx", 0x0A), ("tx", 0x56), ("tx", 0x31), ("tx", 0x0D), ("tx", 0x0A),
         ("rx", 0x43), ("tx", 0x53)]))
    events = sim.parse_trace(text)
    assert sim.sent_lines(events) == [(20, "V1")]
    assert sim.sent_lines(events, last=True) == [(50, "V1")]
    assert sim.sent_lines(events, kind="uart rx", last=True) == [(10, "V")]
    assert sim.sent_lines(events, since=60) == []
    with pytest.raises(ValueError, match="kind 'uart': one of 'uart tx', 'uart rx'"):
        sim.sent_lines(events, kind="uart")


def test_paths_are_relative_to_the_repository():
    assert (sim.REPO_ROOT / "host" / "orfa" / "sim.py").is_file()
    assert sim.sim_path() == sim.REPO_ROOT / "build" / "sim" / "orfa-sim"
    assert sim.firmware_path("m128s") == sim.REPO_ROOT / "build" / "m128s-gate" / "orfa.elf"


def test_missing_firmware_says_how_to_build(tmp_path):
    board = sim.SimBoard("m32d", firmware=tmp_path / "none.elf")
    with pytest.raises(sim.SimError) as exc:
        board.start()
    assert "make all-boards sim" in str(exc.value)
    assert board.proc is None


def test_unknown_board():
    with pytest.raises(ValueError):
        sim.SimBoard("m8")


def test_a_slave_without_an_elf_runs_the_build_for_its_address():
    # ("m128s", 0x10) as `--slave m128s:0x10` and the pytest marker take it:
    # the slave build for that address (it was a ValueError: not enough
    # values to unpack)
    robot = sim.SimRobot("m32d", slaves=[("m128s", 0x10), ("m32d", 0x12, None),
                                         ["m128s", 0x14, "/x/orfa.elf"]])
    assert robot.slaves == (("m128s", 0x10, None), ("m32d", 0x12, None),
                            ("m128s", 0x14, "/x/orfa.elf"))
    assert robot.slave_options == [
        "m128s:0x10:%s" % sim.slave_firmware_path("m128s", 0x10),
        "m32d:0x12:%s" % sim.slave_firmware_path("m32d", 0x12),
        "m128s:0x14:/x/orfa.elf"]


@pytest.mark.parametrize("spec, message", [
    (("m128s",), "slave ('m128s',): (board, addr) or (board, addr, elf), e.g. (\"m128s\", 0x10)"),
    ("m128s:0x10", "slave 'm128s:0x10': (board, addr) or (board, addr, elf)"),
    (("m128s", "0x10"), "slave ('m128s', '0x10'): (board, addr) or (board, addr, elf)"),
    (("m64", 0x10), "slave board 'm64': one of m32d, m128s"),
    (("m128s", 0x11), "slave address 0x11: an 8-bit address, even, 0x10..0xEE"),
    (("m128s", 0x08), "slave address 0x08: an 8-bit address, even, 0x10..0xEE"),
])
def test_a_slave_that_is_no_slave_is_one_line(spec, message):
    with pytest.raises(ValueError) as exc:
        sim.SimRobot("m32d", slaves=[spec])
    assert str(exc.value).startswith(message) and "\n" not in str(exc.value)


def test_parts_become_part_options():
    board = sim.SimBoard("m32d", parts=[("bmp280", 0xEC), ("24lc32", 0xA8, "wp"),
                                        ["24lc32", 0xA0, ""]])
    cmd = board.command()
    assert [cmd[i + 1] for i, arg in enumerate(cmd) if arg == "--part"] == [
        "bmp280@0xEC", "24lc32@0xA8:wp", "24lc32@0xA0"]


@pytest.mark.parametrize("spec, message", [
    ("bmp280@0xEC", "a part is (KIND, ADDR) or (KIND, ADDR, OPTIONS), not 'bmp280@0xEC'"),
    (("bmp280",), "a part is (KIND, ADDR) or (KIND, ADDR, OPTIONS), not ('bmp280',)"),
    (("bmp280", "0xEC"), "part ('bmp280', '0xEC'): ADDR must be an 8-bit bus address"),
    (("bmp280", 0x1EC), "part ('bmp280', 492): ADDR must be an 8-bit bus address"),
])
def test_a_part_that_is_no_part_is_one_line(spec, message):
    with pytest.raises(ValueError) as exc:
        sim.SimBoard("m32d", parts=[spec])
    assert str(exc.value).startswith(message) and "\n" not in str(exc.value)
