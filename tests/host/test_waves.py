"""orfa.vcd, orfa.waves, orfa.plot and the `orfa plot` command on VCD text
written here (the simulator's own VCDs: tests/sim/test_plot.py)."""

import argparse
import re
import struct

import pytest

from orfa import boardmap, decode, plot, vcd, waves
from orfa.cli import main
from orfa.cli import plot as cli_plot

import wavegen

F = boardmap.F_CPU
PS = 1e12 / F
#: The simulator's timescale at 7.3728 MHz: 100 ns, the longest power of
#: ten not longer than a cycle (135.6 ns). Older files have 1 ps.
UNITS = {"100ns": 100000, "1ps": 1}


def vcd_time(cycle, unit_ps):
    """CYCLE's time in units of UNIT_PS, rounded half up as the simulator does."""
    return (2 * cycle * 10 ** 12 + F * unit_ps) // (2 * F * unit_ps)


M32D_PINS = tuple("%s%d" % (p, b) for p in "ABCD" for b in range(8))


def make_vcd(changes, names=M32D_PINS + ("servo3", "i2c"), slave=(), timescale="100ns"):
    """A VCD as the simulator writes it: changes {name: [(cycle, level)]}."""
    ids = {}
    out = ["$comment orfa-sim, %d Hz: one CPU cycle is %.3f ps $end" % (F, PS),
           "$timescale %s $end" % timescale, "$scope module board $end"]
    for i, n in enumerate(names):
        ids[n] = chr(33 + i) + "!"
        out.append("$var wire 1 %s %s $end" % (ids[n], n))
    out.append("$upscope $end")
    if slave:
        out.append("$scope module board_10 $end")
        for i, n in enumerate(slave):
            ids[n] = chr(33 + i) + "#"
            out.append("$var wire 1 %s %s $end" % (ids[n], n))
        out.append("$upscope $end")
    out += ["$enddefinitions $end", "#0", "$dumpvars"]
    out += ["0%s" % ids[n] for n in list(names) + list(slave)]
    out.append("$end")
    events = sorted((c, n, lv) for n, es in changes.items() for c, lv in es)
    last = None
    for c, n, lv in events:
        if c != last:
            out.append("#%d" % vcd_time(c, UNITS[timescale]))
            last = c
        out.append("%d%s" % (lv, ids[n]))
    return "\n".join(out) + "\n"


SERVO = [(1000, 1), (12059, 0), (148456, 1), (159517, 0), (295912, 1), (306971, 0)]


def test_vcd_cycles_are_exact():
    t = vcd.parse(make_vcd({"servo3": SERVO}))
    assert t.f_cpu == F
    assert t.names() == list(M32D_PINS) + ["servo3", "i2c"]
    assert t.edges("servo3") == SERVO
    assert t.initial["servo3"] == 0 and t.end == 306971


@pytest.mark.parametrize("timescale", sorted(UNITS))
def test_vcd_cycles_are_exact_at_both_timescales_over_hours(timescale):
    """Every cycle of a stretch, consecutive ones included, and cycles ten
    hours in come back exact from 100 ns (1.36 units a cycle) and 1 ps."""
    far = 10 * 3600 * F + 1
    edges = [(c, c % 2) for c in list(range(1, 3001)) + list(range(far, far + 3000))]
    t = vcd.parse(make_vcd({"servo3": edges}, timescale=timescale))
    assert t.edges("servo3") == edges


def test_vcd_slave_scope_keeps_its_prefixed_names():
    t = vcd.parse(make_vcd({"10/servo3": [(5, 1)]}, slave=("10/servo3",)))
    assert t.scopes["board_10"] == ["10/servo3"]
    assert t.edges("10/servo3") == [(5, 1)]


@pytest.mark.parametrize("text, message", [
    ("", "no $enddefinitions"),
    ("$timescale 1ps $end\n$enddefinitions $end\n", "no CPU clock"),
    ("$comment 8000000 Hz $end\n$timescale 3ps $end\n", "timescale"),
    ("$comment 8000000 Hz $end\n$timescale 1ps $end\n$enddefinitions $end\n#0\n1?\n",
     "unknown id"),
    ("$comment 8000000 Hz $end\n$timescale 1ps $end\n$enddefinitions $end\n#x\n", "time"),
])
def test_vcd_errors_name_the_place(text, message):
    with pytest.raises(vcd.VcdError, match=re.escape(message)):
        vcd.parse(text, where="t.vcd")


def test_window_and_pulses():
    w = waves.window("servo3", 0, SERVO, 100000, 300000)
    assert w.level == 0 and w.edges == ((148456, 1), (159517, 0), (295912, 1))
    assert waves.pulses(w) == [(148456, 159517)]
    w = waves.window("servo3", 0, SERVO, 150000, 300000)
    assert w.level == 1                          # inside a pulse: it began before
    assert waves.pulses(w) == []                 # no whole high pulse in the window
    assert waves.high_time(w) == (159517 - 150000) + (300000 - 295912)
    s = waves.summary(waves.window("servo3", 0, SERVO, 0, 400000))
    assert (s.pulses, s.width_min, s.width_max) == (3, 11059, 11061)
    assert s.period == (295912 - 1000) // 2 and s.polarity == 1
    assert s.duty == pytest.approx((11059 + 11061) / (295912 - 1000))
    assert waves.describe(s, F) == \
        "high 1500.0 us-1500.2 us, period 20.00 ms (50.0 Hz), duty 7.5%"


def test_a_line_that_idles_high_has_low_pulses():
    cs = [(100, 1), (1000, 0), (1737, 1)]        # a chip select: high, 100 ns low, high
    s = waves.summary(waves.window("B3", 0, cs, 500, 5000))
    assert s.polarity == 0 and (s.width_min, s.width_max) == (737, 737)
    assert waves.describe(s, F) == "low 99.96 us"
    assert waves.describe(waves.summary(waves.window("B3", 1, [], 0, 9)), F) == "steady 1"


def test_a_line_that_only_rises_or_falls_says_when():
    rise = waves.summary(waves.window("B0", 0, [(73728, 1)], 0, 100000))
    assert waves.describe(rise, F) == "rises at 10.00 ms"
    # counted from where the plot's axis starts
    assert waves.describe(rise, F, origin=73728 - 737) == "rises at 99.96 us"
    fall = waves.summary(waves.window("B0", 1, [(737, 0)], 0, 100000))
    assert waves.describe(fall, F) == "falls at 99.96 us"
    # a whole period, rise to rise, around one whole high pulse
    odd = waves.summary(waves.window("B0", 0, [(100, 1), (200, 0), (300, 1)], 0, 310))
    assert waves.describe(odd, F) == "high 13.56 us, period 27.13 us (36.9 kHz), duty 50.0%"
    # mostly high, but the one whole pulse is high: that is what it measures
    long = waves.summary(waves.window("B0", 0, [(100, 1), (900, 0)], 0, 1000))
    assert (long.polarity, long.width_min) == (1, 800)


def test_a_zero_clock_is_no_vcd():
    with pytest.raises(vcd.VcdError, match="no CPU clock"):
        vcd.parse("$comment orfa-sim, 0 Hz $end\n$timescale 1ps $end\n$enddefinitions $end\n")


def test_an_edge_at_the_files_last_time_is_drawn(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    src = tmp_path / "t.vcd"
    src.write_text(make_vcd({"B0": [(73728, 1)]}))
    assert vcd.parse(src.read_text()).end == 73728
    assert main(["plot", str(src), "--signals", "B0", "-o", str(tmp_path / "t.png")]) == 0
    # the window is trimmed to the edge, 50 us (369 cycles) either side
    assert capsys.readouterr().out == "B0         rises at 50.05 us\n"


@pytest.mark.parametrize("text, us", [("1500", 1500), ("1500us", 1500), ("1.5ms", 1500),
                                      ("0.02s", 20000), (".5ms", 500)])
def test_times(text, us):
    assert cli_plot.parse_time(text) == us


@pytest.mark.parametrize("text", ["", "1.5 min", "-3", "ms"])
def test_bad_times(text):
    with pytest.raises(argparse.ArgumentTypeError):
        cli_plot.parse_time(text)


def test_labels_come_from_the_board_map():
    m32 = cli_plot.Namer(["A3", "D5", "servo3", "i2c"] + ["%s%d" % (p, b) for p in "ABCD"
                                                          for b in range(8)])
    assert m32.maps[""].board == "m32d"
    assert m32.label("A3") == "A3\nservo 3"
    motor = boardmap.load("m32d").pins_of("MOTOR_PWM")[0]
    pin = motor.signal
    assert "motor %d PWM" % (motor.index + 1) in m32.label(pin)
    assert m32.label("servo3") == "servo3\npin A3"
    assert m32.label("i2c") == "i2c\nbus busy"
    assert m32.rank("servo3") is None            # its pin's row is the servo's
    m128 = cli_plot.Namer(["servo3"] + ["%s%d" % (p, b) for p in "ABCDEFG" for b in range(8)])
    assert m128.maps[""].board == "m128s"
    assert m128.rank("servo3") == 0
    clk = boardmap.load("m128s").pins_of("SERVO_CLK")[0]
    assert m128.rank(clk.signal) is None


def test_select_by_pattern_keeps_the_order_and_refuses_unknown_names():
    names = ["A3", "B3", "servo3", "servo4", "i2c"]
    namer = cli_plot.Namer(names, {"": "m32d"})
    assert cli_plot.select(namer, names, [], ["i2c", "servo*"]) == (["i2c", "servo3", "servo4"], 0)
    assert cli_plot.select(namer, names, [], ["a3", "SERVO4"]) == (["A3", "servo4"], 0)
    with pytest.raises(Exception, match="no signal 'servo99'"):
        cli_plot.select(namer, names, [], ["servo99"])


def test_annotations_are_the_measured_widths():
    w = waves.window("servo3", 0, SERVO, 0, 400000)
    notes = plot.annotations([plot.Row(w, "servo3")], F)
    assert [(a.kind, a.text, a.cycles) for a in notes] == [
        ("pulse", "1500.0 us", 11059), ("pulse", "1500.2 us", 11061),
        ("pulse", "1500.0 us", 11059),
        ("summary", "high 1500.0 us-1500.2 us, period 20.00 ms (50.0 Hz), duty 7.5%", None)]


def png_size(path):
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_command_on_a_file(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    src = tmp_path / "t.vcd"
    src.write_text(make_vcd({"servo3": SERVO, "A3": SERVO, "i2c": [(50000, 1), (57000, 0)]}))
    out = tmp_path / "t.png"
    assert main(["plot", str(src), "-o", str(out)]) == 0
    assert capsys.readouterr().out == (
        "A3         high 1500.0 us-1500.2 us, period 20.00 ms (50.0 Hz), duty 7.5%\n"
        "i2c        high 949.4 us, 1 pulse\n")
    width, height = png_size(out)
    assert width > 1000 and height > 150
    assert main(["plot", str(src), "--signals", "servo3", "--from", "0", "--to", "15ms",
                 "-o", str(out), "-v"]) == 0
    assert capsys.readouterr().out == ("servo3     1500.0 us\n"
                                       "servo3     high 1500.0 us\n")


def svg_texts(path):
    """The texts of a matplotlib SVG, in order (each is drawn as paths
    after a comment that carries it)."""
    return re.findall(r"<!-- (.*?) -->", path.read_text())


@pytest.mark.parametrize("start, end, unit, label", [
    (0, 7373, "us", "time (\u00b5s) from power-up, simulated, 7.373 MHz CPU clock"),
    (2742682, 2742682 + 331776, "ms",
     "time (ms) from 372.00 ms after power-up, simulated, 7.373 MHz CPU clock"),
    (F * 10, F * 610, "s", "time (s) from 10.00 s after power-up, simulated,"
                           " 7.373 MHz CPU clock"),
])
def test_the_time_axis_counts_from_the_windows_start(start, end, unit, label):
    axis = plot.time_axis(start, end, F)
    assert (axis.origin, axis.unit, axis.label) == (start, unit, label)


def test_a_window_is_drawn_from_its_start_in_readable_units(tmp_path, capsys):
    # a servo pulsing from 370 ms on; --from 372ms --to 417ms is drawn as
    # 0..45 ms, not as 372000..417000 us since power-up
    pytest.importorskip("matplotlib")
    period, start = 147456, 2727936                     # 20 ms; 370 ms
    servo = [e for k in range(40) for e in ((start + k * period, 1),
                                            (start + k * period + 11059, 0))]
    src = tmp_path / "t.vcd"
    src.write_text(make_vcd({"A3": servo}))
    out = tmp_path / "t.svg"
    assert main(["plot", str(src), "--signals", "A3", "--from", "372ms", "--to", "417ms",
                 "-o", str(out)]) == 0
    texts = svg_texts(out)
    label = [t for t in texts if t.startswith("time (")]
    assert label == ["time (ms) from 372.00 ms after power-up, simulated, 7.373 MHz CPU clock"]
    ticks = [int(t) for t in texts if t.isdigit()]
    assert ticks[0] == 0 and ticks[-1] == 45 and ticks == sorted(ticks), ticks
    assert "372000" not in out.read_text()
    assert capsys.readouterr().out == \
        "A3         high 1500.0 us, period 20.00 ms (50.0 Hz), duty 7.5%\n"


def bus_vcd(tmp_path):
    """A board's life as `orfa sim --vcd` writes it: the SPI chip select and
    the UART's receive line go high at power-up; 300 ms and 500 ms later a
    request each (bytes on RX, then a bus transaction); the file ends at
    10 minutes."""
    ms = F // 1000
    rx = [(500, 1)]
    i2c = []
    for t in (300 * ms, 500 * ms):
        for byte in range(5):                      # a start bit and a zero bit a byte
            b = t + byte * 640
            rx += [(b, 0), (b + 64, 1), (b + 320, 0), (b + 384, 1)]
        i2c += [(t + 4000, 1), (t + 4000 + 2944, 0)]
    src = tmp_path / "bus.vcd"
    src.write_text(make_vcd({"B4": [(7143, 1)], "D0": rx, "i2c": i2c,
                             "B0": [(600 * 1000 * ms, 1)]}))
    return src


def test_a_window_is_trimmed_to_where_the_activity_is(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "bus.svg"
    assert main(["plot", str(bus_vcd(tmp_path)), "-o", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    # the chip select's power-up edge and a pin set ten minutes later are
    # not what happened: the rows are the bus and the serial line, and the
    # window is their 200 ms and 5 % of that either side (10 ms before the
    # first byte at 299.97 ms)
    assert [line.split()[0] for line in lines] == ["i2c", "D0"]
    texts = svg_texts(out)
    label = [t for t in texts if t.startswith("time (")]
    assert label == ["time (ms) from 289.92 ms after power-up, simulated, 7.373 MHz CPU clock"]
    ticks = [int(t) for t in texts if t.isdigit()]
    assert ticks[0] == 0 and 200 <= ticks[-1] <= 220, ticks


def test_bus_and_serial_rows_count_their_pulses_without_a_period(tmp_path, capsys):
    # a transaction or a byte comes when there is one to send: a period of
    # 200 ms (5 Hz) and a duty of 0.2 % would mean nothing
    pytest.importorskip("matplotlib")
    assert main(["plot", str(bus_vcd(tmp_path)), "--signals", "i2c", "D0", "B4",
                 "-o", str(tmp_path / "bus.png")]) == 0
    assert capsys.readouterr().out == ("i2c        high 399.3 us, 2 pulses\n"
                                       "D0         low 8.68 us, 20 pulses\n"
                                       "B4         steady 1\n")


@pytest.mark.parametrize("argv, message", [
    (["plot", "-o", "x.png"], "orfa: give a VCD file"),
    (["plot", "nowhere.vcd", "-o", "x.png"], "orfa: cannot read nowhere.vcd: No such file"),
    (["plot", "{vcd}", "--signals", "servo99", "-o", "x.png"], "orfa: no signal 'servo99'"),
    (["plot", "{vcd}", "--from", "2ms", "--to", "1ms", "-o", "x.png"],
     "orfa: --to must be after --from"),
    (["plot", "{vcd}", "--do", "servo 3 1500", "-o", "x.png"], "orfa: --do runs commands"),
    (["plot", "{bad}", "-o", "x.png"], "orfa: {bad}: no $enddefinitions"),
    (["plot", "--control", "{tmp}/none.sock", "-o", "x.png"], "orfa: cannot connect to"),
    (["plot", "--sim", "m32d", "--control", "{tmp}/none.sock", "-o", "x.png"],
     "orfa: give --sim (a board of its own) or --control (a running one), not both"),
])
def test_command_errors_are_one_line(tmp_path, capsys, argv, message):
    good, bad = tmp_path / "t.vcd", tmp_path / "bad.vcd"
    good.write_text(make_vcd({"servo3": SERVO}))
    bad.write_text("hello\n")
    fill = dict(vcd=good, bad=bad, tmp=tmp_path)
    argv = [a.format(**fill) for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(message.format(**fill)) and err.count("\n") == 1
    assert not (tmp_path / "x.png").exists()


# --- decoded rows: the serial line's bytes, the I2C bus's frames ---------------

BIT = F // 115200                                  # the gateway's default rate: 64 cycles


def serial_vcd(tmp_path, request=b"S A0 10 41 P\r", reply=b"SWAAAP\r\n"):
    """The PC's request on RXD (D0) and the board's reply on TXD (D1); the
    file goes on a while after them (B0 moves), as the simulator's does."""
    rx, _ = wavegen.serial(request, BIT, t=10000)
    tx, _ = wavegen.serial(reply, BIT, t=10000 + (len(request) + 20) * 10 * BIT)
    src = tmp_path / "serial.vcd"
    src.write_text(make_vcd({"D0": [(500, 1)] + rx, "D1": [(500, 1)] + tx,
                             "B0": [(tx[-1][0] + 5000, 1)]}))
    return src


def in_order(wanted, texts):
    """Whether WANTED appear in TEXTS in this order (others between them)."""
    it = iter(texts)
    return all(any(t == w for t in it) for w in wanted)


def test_serial_rows_carry_their_decoded_bytes(tmp_path, capsys):
    """Both directions, each byte written over its frame as the character
    it is (CR, LF, SP named); -v prints them instead of the bits' widths."""
    pytest.importorskip("matplotlib")
    out = tmp_path / "serial.svg"
    assert main(["plot", str(serial_vcd(tmp_path)), "--signals", "D0", "D1", "-o", str(out),
                 "-v"]) == 0
    got = {}
    for ln in capsys.readouterr().out.splitlines():
        name, _, text = ln.partition(" ")
        got.setdefault(name, []).append(text.strip())
    request = ["S", "SP", "A", "0", "SP", "1", "0", "SP", "4", "1", "SP", "P", "CR"]
    reply = ["S", "W", "A", "A", "A", "P", "CR", "LF"]
    assert got["D0"][:-1] == request and got["D1"][:-1] == reply
    texts = svg_texts(out)
    drawn = [plot.GLYPHS.get(t, t) for t in request]      # a space drawn as one glyph
    assert in_order(drawn, texts) and in_order(reply, texts)


def test_each_row_is_decoded_once(tmp_path, monkeypatch):
    """The window trimmed to the activity needs the rows' frames, and so
    does the picture: each row's line is read once for both."""
    pytest.importorskip("matplotlib")
    read, uart = [], decode.uart
    monkeypatch.setattr(decode, "uart", lambda wave, bit: read.append(wave.name) or uart(wave, bit))
    assert main(["plot", str(serial_vcd(tmp_path)), "--signals", "D0", "D1",
                 "-o", str(tmp_path / "serial.png")]) == 0
    assert sorted(read) == ["D0", "D1"]


def test_serial_rows_are_decoded_at_the_given_rate(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    rx, _ = wavegen.serial(b"V\r", F // 9600, t=10000)
    src = tmp_path / "slow.vcd"
    src.write_text(make_vcd({"D0": [(500, 1)] + rx, "B0": [(rx[-1][0] + 5000, 1)]}))
    assert main(["--baud", "9600", "plot", str(src), "--signals", "D0", "-v",
                 "-o", str(tmp_path / "slow.png")]) == 0
    assert capsys.readouterr().out.splitlines()[:2] == ["D0         V", "D0         CR"]


def test_decoded_frames_are_read_whole_when_the_window_cuts_them():
    """A window that starts inside a frame: the frames inside it are read
    from the whole line (not from a falling edge inside the cut one), and
    the cut one is not written."""
    rx, starts = wavegen.serial(b"\x00\x41\x42", BIT, t=1000)
    whole = waves.window("D0", 1, rx, 0, 10 ** 6)
    frames = cli_plot.decoded(cli_plot.Namer(list(M32D_PINS)), {"D0": whole}, ["D0"], F, 115200)
    row = plot.Row(waves.clip(whole, starts[0] + 5 * BIT, 10 ** 6), "D0", False, frames["D0"])
    assert [a.text for a in plot.annotations([row], F) if a.kind == "decoded"] == ["A", "B"]


def i2c_vcd(tmp_path):
    """The bus's own wires `sda` and `scl` (the simulator's bit-level bus):
    an EEPROM's random read with a repeated START and the master's NACK, a
    slave that stretches the clock, an absent address."""
    bus = wavegen.Bus(t=5000)
    bus.start()
    for b in (0xA0, 0x10):
        bus.byte(b, True)
    bus.restart()
    bus.byte(0xA1, True)
    bus.byte(0x41, True)
    bus.byte(0x42, False)
    bus.stop()
    bus.t += 500
    bus.start()
    bus.byte(0x10, True)
    bus.byte(0x05, True, stretch=400)              # the slave holds SCL low
    bus.stop()
    bus.t += 500
    bus.start()
    bus.byte(0xE0, False)
    bus.stop()
    src = tmp_path / "bus.vcd"
    idle = {n: [(100, 1)] + es for n, es in bus.edges.items()}     # high from power-up
    src.write_text(make_vcd(idle, names=M32D_PINS + ("i2c", "sda", "scl")))
    return src


I2C_TEXTS = ["S", "A0 W", "A", "10", "A", "Sr", "A1 R", "A", "41", "A", "42", "N", "P",
             "S", "10 W", "A", "05", "A", "P", "S", "E0 W", "N", "P"]


def test_sda_row_carries_the_decoded_i2c(tmp_path, capsys):
    """With wires `sda` and `scl` in the capture, the default rows are the
    bus's (labelled as the I2C bus), and SDA's has START, address + R/W,
    data, ACK/NACK, repeated START and STOP written on it."""
    pytest.importorskip("matplotlib")
    out = tmp_path / "bus.svg"
    assert main(["plot", str(i2c_vcd(tmp_path)), "-o", str(out), "-v"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [ln.split()[0] for ln in lines] == ["sda"] * (len(I2C_TEXTS) + 1) + ["scl"]
    assert [ln[11:] for ln in lines[:len(I2C_TEXTS)]] == I2C_TEXTS
    texts = svg_texts(out)
    assert "sda" in texts and "I2C bus" in texts
    assert in_order(I2C_TEXTS, texts)


def test_with_the_bus_wires_the_twi_pins_are_no_default_rows():
    """The TWI pins (C0/C1 on the M32-D, a slave's 10/D0) carry the bus's
    lines: with the wires sda and scl in the capture, those are the rows."""
    names = list(M32D_PINS) + ["i2c", "sda", "scl", "10/C0"]
    namer = cli_plot.Namer(names, {"": "m32d", "10": "m32d"})
    assert [namer.rank(n) for n in ("sda", "scl", "C0", "C1", "10/C0", "i2c")] == \
        [3, 3, None, None, None, 3]
    assert namer.label("sda") == "sda\nI2C bus" and namer.periodic("scl") is False
    without = cli_plot.Namer(list(M32D_PINS), {"": "m32d"})
    assert without.rank("C0") == 3


def test_without_scl_sda_is_not_decoded(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    bus = wavegen.Bus(t=5000)
    bus.start()
    bus.byte(0xA0, True)
    bus.stop()
    src = tmp_path / "sda.vcd"
    src.write_text(make_vcd({"sda": [(100, 1)] + bus.edges["sda"]}, names=M32D_PINS + ("sda",)))
    assert main(["plot", str(src), "-o", str(tmp_path / "sda.png"), "-v"]) == 0
    assert "A0 W" not in capsys.readouterr().out


def test_decoded_texts_that_would_cover_each_other_are_not_drawn(tmp_path, capsys):
    """Forty bytes in a window of 200 ms: each byte's frame is far narrower
    than its text, so none is written (a few would read as a wrong word);
    -v still prints every one."""
    pytest.importorskip("matplotlib")
    rx, _ = wavegen.serial(b"QZ" * 20, BIT, t=10000)
    src = tmp_path / "dense.vcd"
    src.write_text(make_vcd({"D0": [(500, 1)] + rx, "B0": [(F // 5, 1)]}))
    out = tmp_path / "dense.svg"
    assert main(["plot", str(src), "--signals", "D0", "--from", "0", "--to", "200ms", "-v",
                 "-o", str(out)]) == 0
    assert capsys.readouterr().out.splitlines()[:40] == ["D0         Q", "D0         Z"] * 20
    texts = svg_texts(out)
    assert "Q" not in texts and "Z" not in texts
