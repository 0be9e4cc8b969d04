"""`orfa plot` on the simulator's own waveforms: what it measures in a VCD is
what the control socket's `measure` saw on the pin, the bus's `i2c` signal
spans the trace's START..STOP, and the live forms (--sim, --control) draw
the servo a command moved. The pictures go to $ORFA_SHOTS (build/shots;
`make doc-images` puts them in docs/img)."""

import os
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from orfa import boardmap, vcd, waves
from orfa.board import Board
from orfa.sim import SimBoard

from conftest import require_builds

ROOT = Path(__file__).resolve().parents[2]
ENV = dict(os.environ, PYTHONPATH=str(ROOT / "host"))
SHOTS = Path(os.environ.get("ORFA_SHOTS", str(ROOT / "build" / "shots")))

pytest.importorskip("matplotlib")


def orfa(*args):
    return subprocess.run([sys.executable, "-m", "orfa"] + [str(a) for a in args], env=ENV,
                          capture_output=True, text=True, timeout=120)


def png_size(path):
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def rows(stdout):
    """`NAME  TEXT` lines -> {name: [texts]}."""
    out = {}
    for line in stdout.splitlines():
        name, _, text = line.partition(" ")
        out.setdefault(name, []).append(text.strip())
    return out


def us_values(text):
    return [float(v) for v in re.findall(r"([\d.]+) us", text)]


@pytest.mark.parametrize("board", boardmap.BOARDS)
def test_vcd_widths_are_what_the_pin_measured(board, tmp_path):
    require_builds([board])
    f_cpu = boardmap.load(board).f_cpu
    sim = SimBoard(board, control=True, vcd=True, trace=False).start()
    try:
        with sim.gateway() as gw:
            Board(gw).servo.set_widths({3: 1500, 6: 1234})
        ctl = sim.control
        since = ctl.time() + int(0.025 * f_cpu)     # by then the new widths are on
        # one batch: both measured at the cycle the wait ends
        replies = ctl.requests(["wait %d" % int(0.15 * f_cpu)] +
                               ["measure servo%d 50 %d" % (ch, since) for ch in (3, 6)])
        end = int(replies[0])
        measured = {3: replies[1].split(), 6: replies[2].split()}
        sim.stop(keep_dir=True)
        trace = vcd.load(str(sim.vcd_path))
    finally:
        sim.stop()
    assert trace.f_cpu == f_cpu and trace.board_of() == {"": board}
    for ch, m in measured.items():
        name = "servo%d" % ch
        # measure takes whole periods, rise to rise: the window ends at the
        # last rise before the batch's cycle
        last_rise = max(c for c, lv in trace.edges(name) if lv == 1 and c < end)
        w = waves.window(name, trace.initial[name], trace.edges(name), since, last_rise)
        s = waves.summary(w)
        assert m[0] == "high" and s.polarity == 1 and s.pulses == int(m[m.index("n") + 1]) >= 5
        # the same edges: the exact extremes measure reports, in cycles
        assert (s.width_min, s.width_max) == (int(m[1]), int(m[2]))
        assert abs(waves.us(s.width_min, f_cpu) - (1500 if ch == 3 else 1234)) < 1


def test_i2c_signal_spans_start_to_stop(tmp_path):
    require_builds(["m32d"])
    sim = SimBoard("m32d", eeproms=(0xA0,), control=True, vcd=True).start()
    try:
        mark = sim.trace_mark()
        with sim.gateway() as gw:
            assert gw.request("S A0 10 41 42 P") == "SWAAAP"
            assert gw.request("S A0 10 S A1 02 P") == "SWASR4142P"
        sim.control.wait(20000)
        events = sim.trace_events(mark, kinds=["twi"])
        sim.stop(keep_dir=True)
        sim_vcd = tmp_path / "bus.vcd"
        sim_vcd.write_bytes(sim.vcd_path.read_bytes())
        trace = vcd.load(str(sim_vcd))
    finally:
        sim.stop()
    busy = []
    for e in events:
        if e.kind == "twi start" and (not busy or busy[-1][1] == 0):
            busy.append((e.cycle, 1))
        elif e.kind == "twi stop":
            busy.append((e.cycle, 0))
    assert len(busy) == 4                        # two transfers, the second with a repeated START
    assert [e for e in trace.edges("i2c") if e[0] >= busy[0][0]] == busy

    # the command draws them with the serial line that asked for them
    SHOTS.mkdir(parents=True, exist_ok=True)
    out = SHOTS / "plot-bus.png"
    f_cpu = trace.f_cpu
    r = orfa("plot", sim_vcd, "--from", "%.3f" % waves.us(busy[0][0] - 30000, f_cpu),
             "--to", "%.3f" % waves.us(busy[-1][0] + 3000, f_cpu), "-v", "-o", out)
    assert r.returncode == 0, r.stderr
    got = rows(r.stdout)
    widths = [round(v * f_cpu / 1e6) for t in got["i2c"][:-1] for v in us_values(t)]
    assert [abs(w - (stop - start)) <= 1 for w, ((start, _), (stop, _)) in
            zip(widths, [busy[0:2], busy[2:4]])] == [True, True]
    assert "D0" in got or "D2" in got            # the UART line's bytes (RX pin)
    png_size(out)


def test_live_board_with_sim(tmp_path):
    require_builds(["m32d"])
    SHOTS.mkdir(parents=True, exist_ok=True)
    out = SHOTS / "plot-servo.png"
    motor = boardmap.load("m32d").pins_of("MOTOR_PWM")[0]
    pwm = motor.signal
    r = orfa("--sim", "m32d", "plot", "--do", "servo 3 1500", "--do", "servo 5 --angle 45",
             "--do", "motor %d 100" % (motor.index + 1), "--signals", "servo3", "servo5", pwm,
             "--from", "0", "--to", "45ms", "-v", "-o", out)
    assert r.returncode == 0, r.stderr
    got = rows(r.stdout)
    assert set(got) == {"servo3", "servo5", pwm}
    widths3 = [v for t in got["servo3"][:-1] for v in us_values(t)]
    assert len(widths3) >= 2 and all(abs(v - 1500) <= 0.5 for v in widths3)
    assert "period 20.00 ms (50.0 Hz)" in got["servo3"][-1]
    # +45 degrees: 1500 + 45 * 500/75 us
    assert all(abs(v - 1800) <= 0.5 for t in got["servo5"][:-1] for v in us_values(t))
    assert re.search(r"period 4\d\.\d\d us \(2\d\.\d kHz\), duty 39\.\d%", got[pwm][-1])
    width, height = png_size(out)
    assert width > 1000 and height > 200


@pytest.mark.parametrize("board, line", [("m32d", ["--baud", "460800"]),
                                         ("m128s", ["--baud", "230400"]),
                                         ("m32d", ["--baud", "230400", "--autobaud"])])
def test_live_board_with_sim_at_a_fast_rate(board, line, tmp_path):
    """`orfa --sim B --baud 460800 plot --do ...` simulates the gateway built
    for that rate (as every --sim command does) and its commands talk at it:
    the board was the 115200 build, and the first --do got no reply."""
    require_builds([board])
    r = orfa("--sim", board, *line, "plot", "--do", "servo 3 1500", "--for", "25ms",
             "--signals", "servo3", "-o", tmp_path / "p.png")
    assert (r.returncode, r.stderr) == (0, "")
    assert r.stdout.startswith("servo3     high ")
    assert r.stdout.endswith(" us, period 20.00 ms (50.0 Hz), duty 7.5%\n")
    widths = us_values(r.stdout)
    assert widths and all(abs(v - 1500) <= 1.1 for v in widths), r.stdout


def test_live_window_is_drawn_from_zero_in_ms(tmp_path):
    # --from 0 --to 45ms live is the 45 ms after the commands: the axis
    # runs 0..45 ms (it was microseconds since power-up, 372000-417000)
    require_builds(["m32d"])
    out = tmp_path / "servo.svg"
    r = orfa("--sim", "m32d", "plot", "--do", "servo 3 1500", "--signals", "servo3",
             "--from", "0", "--to", "45ms", "-o", out)
    assert r.returncode == 0, r.stderr
    texts = re.findall(r"<!-- (.*?) -->", out.read_text())
    (label,) = [t for t in texts if t.startswith("time (")]
    assert re.fullmatch(r"time \(ms\) from \d+\.\d\d ms after power-up, simulated,"
                        r" 7\.373 MHz CPU clock", label), label
    ticks = [int(t) for t in texts if t.isdigit()]
    assert ticks[0] == 0 and ticks[-1] == 45 and ticks == sorted(ticks), ticks


def test_live_board_through_its_control_socket(tmp_path):
    require_builds(["m128s"])
    sim = SimBoard("m128s", control=True, trace=False).start()
    try:
        out = tmp_path / "live.png"
        rx = boardmap.load("m128s").pins_of("UART_RX")[0].signal
        r = orfa("plot", "--control", sim.control_path, "--port", sim.port,
                 "--do", "servo 20 1200", "--signals", "servo20", rx, "--for", "45ms", "-v",
                 "-o", out)
        assert r.returncode == 0, r.stderr
        # the recording starts when the command has had its reply: the
        # request's bytes on the receive line are before it
        assert rows(r.stdout)[rx] == ["steady 1"]
        got = rows(r.stdout)["servo20"]
        widths = [v for t in got[:-1] for v in us_values(t)]
        assert len(widths) >= 2 and all(abs(v - 1200) <= 0.5 for v in widths)
        m = sim.control.measure("servo20", n=2)
        high = [waves.us(c, boardmap.load("m128s").f_cpu) for c in m["high"][:2]]
        assert all(abs(h - 1200) <= 0.5 for h in high)
        png_size(out)
    finally:
        sim.stop()


def test_live_command_that_fails_stops_the_plot(tmp_path):
    require_builds(["m32d"])
    out = tmp_path / "x.png"
    r = orfa("--sim", "m32d", "plot", "--do", "servo 3 99999", "-o", out)
    assert r.returncode == 2
    assert r.stderr.splitlines()[-1] == "orfa: --do 'servo 3 99999' failed (exit 2)"
    assert not out.exists()
