"""Servo driver (docs/registers.md "Servos"), measured on the pins.

M32-D: channel n's pin from docs/boards.md; M128-S: the simulator's
`servo<n>` signals (output Q(1 + n % 8) of CD4017 counter n / 8). Widths
must be within 1.1 us = 8 cycles of the commanded width, the period 20 ms
+-0.1 %.
"""

import pytest

from conftest import F_CPU, SERVO_FRAME, WIDTH_TOL, us_to_cycles
from orfa.simctl import SimControlError

PERIOD_TOL = SERVO_FRAME // 1000    # 0.1 %: 147 cycles
BAD_LENGTH, BAD_VALUE, PIN_BUSY = 0x01, 0x02, 0x03
#: docs: an off channel on a counter with pulsing channels: a pulse of 1-30 us.
OFF_PULSE_US = (1, 30)


def sp(drv):
    return drv.lay["servo"] + 1


def rs(drv):
    return drv.lay["servo"]


def set_widths(drv, widths):
    """{channel: us} in writes of at most 16 triples."""
    items = sorted(widths.items())
    for i in range(0, len(items), 16):
        drv.wr(sp(drv), b"".join(bytes([ch, w >> 8, w & 0xFF]) for ch, w in items[i:i + 16]))


def settle(drv, frames=5):
    """Wait until new widths run (they start at the next frame), then
    record at least 5 frames; returns the cycle the recording began."""
    frames = max(frames, 5)
    drv.wait(2 * SERVO_FRAME + 8192)
    since = drv.now()
    drv.wait(frames * SERVO_FRAME)
    return since


def check_pulses(drv, sig, us, since, min_periods=3):
    m = drv.measure(sig, since)
    assert "high" in m, (sig, us, m)
    want = us_to_cycles(us)
    lo, hi, _ = m["high"]
    assert m["n"] >= min_periods, (sig, m)
    assert abs(lo - want) <= WIDTH_TOL and abs(hi - want) <= WIDTH_TOL, (
        "%s: %d us = %.1f cycles, measured high %d..%d" % (sig, us, want, lo, hi))
    plo, phi, _ = m["period"]
    assert abs(plo - SERVO_FRAME) <= PERIOD_TOL and abs(phi - SERVO_FRAME) <= PERIOD_TOL, (
        "%s: period %d..%d, want %d +-%d" % (sig, plo, phi, SERVO_FRAME, PERIOD_TOL))
    return lo - want, hi - want


def check_silent(drv, sig, since):
    assert drv.edges(sig, since) == [], sig
    assert drv.ctl.level(sig) == 0, sig


def channels(drv):
    return range(drv.lay["servo_channels"])


# --- widths on every channel --------------------------------------------------

@pytest.mark.parametrize("command, expected", [
    (500, 500), (1500, 1500), (2500, 2500),
    (0x0064, 500),          # clamped up
    (3000, 2500),           # clamped down
])
def test_width_on_every_channel(drv, command, expected):
    """Even channels, then odd channels, at the width (the others at 1000 us,
    so no M128-S counter's widths add up to more than 19.8 ms)."""
    for parity in (0, 1):
        widths = {ch: (command if ch % 2 == parity else 1000) for ch in channels(drv)}
        set_widths(drv, widths)
        since = settle(drv)
        for ch in channels(drv):
            sig = drv.lay["servo_pins"][ch]
            check_pulses(drv, sig, expected if ch % 2 == parity else 1000, since)
        want = b"".join((expected if ch % 2 == parity else 1000).to_bytes(2, "big")
                        for ch in channels(drv))
        for first in range(0, len(widths), 16):
            drv.wr(sp(drv), bytes([first]))
            assert drv.rd(sp(drv), 32) == want[2 * first:2 * first + 32]
        drv.wr(sp(drv), b"\x00")


def test_m32d_pulse_start_offsets(drv):
    """M32-D: channel n starts n x 1.111 ms (8191 cycles) after channel 0."""
    if drv.board != "m32d":
        pytest.skip("M32-D only")
    set_widths(drv, {ch: 1000 for ch in channels(drv)})
    since = settle(drv, 2)
    rise0 = drv.highs(drv.lay["servo_pins"][0], since)[0][0]
    for ch in channels(drv):
        rises = [r for r, _, _ in drv.highs(drv.lay["servo_pins"][ch], rise0)]
        assert abs(rises[0] - rise0 - 8191 * ch) <= WIDTH_TOL, (ch, rises[0] - rise0)


@pytest.mark.parametrize("widths", [{0: 1000, 13: 1500}, {1: 1096, 10: 1500}])
def test_m32d_long_gaps_keep_the_starts(drv, widths):
    """M32-D: more than 65535 cycles between two edges (channels far apart)
    still start each channel n x 8191 cycles into the frame. {1: 1096,
    10: 1500}: channel 1 ends 65638 cycles before channel 10 starts, so an
    edge time kept to 16 bits would come 102 cycles after it."""
    if drv.board != "m32d":
        pytest.skip("M32-D only")
    set_widths(drv, widths)
    since = settle(drv)
    first, last = sorted(widths)
    rise = drv.highs(drv.lay["servo_pins"][first], since)[0][0]
    later = [r for r, _, _ in drv.highs(drv.lay["servo_pins"][last], rise)]
    assert abs(later[0] - rise - 8191 * (last - first)) <= WIDTH_TOL, (later[0] - rise)
    for ch, us in widths.items():
        check_pulses(drv, drv.lay["servo_pins"][ch], us, since)


def test_m32d_a_channel_not_written_keeps_its_place(drv):
    """M32-D (docs: placing): 5 at 1100 us ends 81 cycles before 6 starts;
    written together, 5 is placed first and 6 moves to the nearest clear
    place, 10 x 32 cycles late. Then 5 alone gets shorter: 6, not written,
    stays where it is; written again, it goes back to its slot."""
    if drv.board != "m32d":
        pytest.skip("M32-D only")
    pins = drv.lay["servo_pins"]

    def starts():
        since = settle(drv, 2)
        rise0 = drv.highs(pins[0], since)[0][0]
        return {ch: drv.highs(pins[ch], rise0)[0][0] - rise0 for ch in (5, 6)}

    set_widths(drv, {0: 1000, 5: 1100, 6: 1200})
    got = starts()
    assert abs(got[5] - 5 * 8191) <= WIDTH_TOL and abs(got[6] - (6 * 8191 + 320)) <= WIDTH_TOL, got
    set_widths(drv, {5: 1000})
    got = starts()
    assert abs(got[5] - 5 * 8191) <= WIDTH_TOL and abs(got[6] - (6 * 8191 + 320)) <= WIDTH_TOL, got
    set_widths(drv, {6: 1201})
    got = starts()
    assert abs(got[6] - 6 * 8191) <= WIDTH_TOL, got
    since = settle(drv, 3)
    for ch, us in ((0, 1000), (5, 1000), (6, 1201)):
        check_pulses(drv, pins[ch], us, since)


#: docs/registers.md: an M32-D write's widths are planned about a
#: millisecond after the write's line ends.
PLAN_WITHIN = F_CPU // 1000


def test_m32d_a_write_starts_at_the_first_frame_after_its_plan(drv):
    """M32-D (docs/registers.md): the board plans a write's edges once its
    reply is queued, and the interrupt takes a plan over when a frame's
    last edge is out, for the next frame. Channel 0 alone (its pulse
    starts the frame and is its last edge), written with its line ending
    from 3 ms before that last edge to 3 ms after: the next frame runs the
    new width when the line ended over PLAN_WITHIN before the last edge,
    the one after when it ended after it; the plan's time is printed."""
    if drv.board != "m32d" or drv.slave:
        pytest.skip("the M32-D gateway's own servos only")
    pin = drv.lay["servo_pins"][0]
    byte = 10 * F_CPU // 115200
    set_widths(drv, {0: 1000})
    settle(drv, 2)
    made, missed = [], []
    for k, d in enumerate(range(-3000, 3001, 250)):
        old, us = (1000, 2000) if k % 2 == 0 else (2000, 1000)
        line = b"SAA%02X00%04XP\n" % (sp(drv), us)
        for _ in range(20):         # a loaded machine's simulator may pass the cycle
            start = drv.highs(pin, drv.now() - 2 * SERVO_FRAME)[-1][0] + 3 * SERVO_FRAME
            last = start + us_to_cycles(old)              # that frame's last edge
            try:
                end = drv.ctl.rx(last + d * F_CPU // 1000000 - len(line) * byte, line)
                break
            except SimControlError as e:
                assert "is past" in str(e), e
        else:
            pytest.fail("the simulator ran past every cycle chosen")
        drv.wait(max(1, start + 3 * SERVO_FRAME - drv.now()))
        assert drv.gw.read_reply() == "SWAAAAP"
        new = [r for r, high, _ in drv.highs(pin, start)
               if abs(high - us_to_cycles(us)) <= WIDTH_TOL]
        # the frame that ran it: the next one's start, or the one after's
        first = [f for f in (start + SERVO_FRAME, start + 2 * SERVO_FRAME)
                 if new and abs(new[0] - f) < 64]
        assert first, (d, start, new[:2])
        taken = first[0] == start + SERVO_FRAME
        if end > last:
            assert not taken, (d, "a plan was taken before its write")
        elif last - end > PLAN_WITHIN:
            assert taken, (d, last - end, "the plan came later than the docs say")
        (made if taken else missed).append(last - end)
    print("\nm32d: a write's plan was ready %d..%d cycles after its line ended" % (
        max([c for c in missed if c > 0], default=0), min(made)))


def test_m32d_edges_in_a_row_whatever_the_timer_phase(drv):
    """M32-D: channel 1 ends 401 cycles before channel 2 starts (moved 320
    late by the planner) and 425 before channel 0 ends: the interrupt makes
    the three edges in one go, about 1300 cycles. Timer2 overflows every
    2048 cycles, at a place in the frame set when the servos start: started
    again and again, some start puts an overflow early in that run, and the
    tick count must not lose it (it did: the interrupt then waited forever
    and the watchdog reset the board). Widths exact, no reset."""
    if drv.board != "m32d":
        pytest.skip("M32-D only")
    pins = drv.lay["servo_pins"]
    mark = drv.mark()
    for attempt in range(24):
        set_widths(drv, {0: 0, 1: 0, 2: 0})
        drv.wait(2 * SERVO_FRAME + 61 * attempt)
        for ch, us in ((1, 1100), (2, 1200), (0, 2323)):
            set_widths(drv, {ch: us})
        since = drv.now() + 2 * SERVO_FRAME
        drv.wait(4 * SERVO_FRAME)
        assert drv.events(mark, ["reset"]) == [], "watchdog reset at start %d" % attempt
        for ch, us in ((0, 2323), (1, 1100), (2, 1200)):
            check_pulses(drv, pins[ch], us, since, 1)
    since = settle(drv, 2)
    rise1 = drv.highs(pins[1], since)[0][0]
    assert abs(drv.highs(pins[2], rise1)[0][0] - rise1 - (8191 + 320)) <= WIDTH_TOL


def test_m128s_long_counter_frame_stretches(drv):
    """M128-S: eight 2500 us widths on one counter (20 ms > 19.8 ms) stretch
    that frame to fit them; the widths stay exact."""
    if drv.board != "m128s":
        pytest.skip("M128-S only")
    set_widths(drv, {ch: 2500 for ch in range(8)})
    drv.wait(2 * SERVO_FRAME)
    since = settle(drv)
    for ch in range(8):
        m = drv.measure("servo%d" % ch, since)
        assert abs(m["high"][0] - 18432) <= WIDTH_TOL and abs(m["high"][1] - 18432) <= WIDTH_TOL, m
        assert m["period"][0] >= 8 * 18432 + 1, m


# --- under load on the serial line ------------------------------------------------

def load_requests(drv, count, w0):
    """Requests in one write, each reply no longer than its request; some
    rewrite channel 0's width (same value), some are RS writes (no effect)."""
    lay = drv.lay
    reqs, replies = [], []
    for i in range(count):
        k = i % 5
        if k == 0:
            reqs.append(drv.req("S AA %02X S AB 02 P" % sp(drv)).encode())
            replies.append(b"SWASR%04XP\r\n" % w0)
        elif k == 1:
            reqs.append(drv.req("S AA %02X 00 %02X %02X P" % (sp(drv), w0 >> 8, w0 & 0xFF)).encode())
            replies.append(b"SWAAAAP\r\n")
        elif k == 2:
            reqs.append(drv.req("S AA %02X 00 P" % rs(drv)).encode())
            replies.append(b"SWAAP\r\n")
        elif k == 3:
            reqs.append(drv.req("S AA %02X S AB 01 P" % lay["gpio_mode"]).encode())
            replies.append(None)
        else:
            reqs.append(b"V    ")
            replies.append(b"V1.1\r\n")
    return reqs, replies


def test_widths_under_uart_load(drv):
    """Widths stay within 1.1 us while 300 requests stream in back to back."""
    if drv.board == "m32d":
        # no edge of one channel near another channel's start (that case
        # has its own test below): even channels 500-920 us, odd 1340-1900 us
        widths = {ch: (500 + 30 * ch if ch % 2 == 0 else 1300 + 40 * ch) for ch in channels(drv)}
    else:
        widths = {ch: 600 + 50 * ch for ch in channels(drv)}
    set_widths(drv, widths)
    drv.wait(3 * SERVO_FRAME)
    reqs, replies = load_requests(drv, 300, widths[0])
    mark = drv.mark()
    t0 = drv.now()
    drv.gw.send(b"".join(r + b"\n" for r in reqs))
    got = drv.read_lines(len(reqs))
    # the load lasts until the last reply byte left the board
    t1 = drv.events(mark, ["uart tx"])[-1].cycle
    drv.assert_silent()
    lines = [l + b"\r\n" for l in got.split(b"\r\n")[:-1]]
    assert t1 - t0 > 10 * SERVO_FRAME          # the load lasted at least 10 frames
    worst = 0.0
    bad = []
    for ch in channels(drv):
        sig = drv.lay["servo_pins"][ch]
        pulses = drv.highs(sig, t0, t1)
        assert len(pulses) >= (t1 - t0) // SERVO_FRAME - 1, (sig, len(pulses))
        want = us_to_cycles(widths[ch])
        for rise, high, period in pulses:
            err = high - want
            worst = max(worst, abs(err))
            if abs(err) > WIDTH_TOL:
                bad.append("%s at %d: high %d, want %.1f" % (sig, rise, high, want))
            if period is not None and rise + period <= t1 and abs(period - SERVO_FRAME) > PERIOD_TOL:
                bad.append("%s at %d: period %d" % (sig, rise, period))
    print("\n%s: servo width error under UART load: max %.1f cycles = %.2f us "
          "over %d frames" % (drv.board, worst, worst * 1e6 / F_CPU,
                              (t1 - t0) // SERVO_FRAME))
    assert bad == [], "%d pulses off (max error %.1f cycles): %s" % (
        len(bad), worst, "; ".join(bad[:12]))
    errors = [l for l in lines if l.startswith(b"ERROR")]
    assert len(lines) == len(reqs) and errors == [], (
        "%d replies to %d requests, %d of them ERROR replies: %r"
        % (len(lines), len(reqs), len(errors), sorted(set(errors))))
    for req, want, line in zip(reqs, replies, lines):
        if want is None:
            assert line[:5] == b"SWASR" and line[-3:] == b"P\r\n", (req, line)
        else:
            assert line == want, (req, line)


def test_m32d_close_edges_keep_their_widths(drv):
    """M32-D: channel 5 at 1100 us ends 81 cycles before channel 6 starts
    (6 x 8191 cycles into the frame); both widths must stay exact."""
    if drv.board != "m32d":
        pytest.skip("M32-D only: edges written by an interrupt")
    set_widths(drv, {5: 1100, 6: 1200})
    since = settle(drv)
    check_pulses(drv, "A5", 1100, since)
    check_pulses(drv, "A6", 1200, since)


def test_widths_while_the_adc_converts(drv):
    """The ADC's conversions (an interrupt every 1664 cycles) must not move
    servo edges (docs: widths exact to a CPU cycle / a timer tick)."""
    if drv.board == "m32d":
        drv.wr(drv.lay["adc"], b"\x01\x03")              # ADC 0-1 = PA0-PA1
        widths = {3: 1500, 8: 1500, 12: 1500, 15: 900}
    else:
        drv.wr(drv.lay["adc"], b"\x01\xff")
        widths = {0: 1500, 9: 1500, 20: 1500, 31: 900}
    set_widths(drv, widths)
    since = settle(drv)
    for ch, w in widths.items():
        check_pulses(drv, drv.lay["servo_pins"][ch], w, since)


# --- off ------------------------------------------------------------------------------

def test_width_0_turns_a_channel_off(drv):
    """M32-D: line low, no pulses. M128-S: the counter is silent once no
    channel on it pulses."""
    pins = drv.lay["servo_pins"]
    chans = [0, 5, 13, 14] if drv.board == "m32d" else [0, 9, 20, 31]
    set_widths(drv, {ch: 1500 for ch in chans})
    since = settle(drv, 2)
    for ch in chans:
        check_pulses(drv, pins[ch], 1500, since, 1)
    set_widths(drv, {chans[0]: 0, chans[1]: 0})
    since = settle(drv, 3)
    for ch in chans[:2]:
        check_silent(drv, pins[ch], since)
    for ch in chans[2:]:
        check_pulses(drv, pins[ch], 1500, since)
    assert drv.rd(sp(drv), 2 * (chans[1] + 1)) == bytes(2 * (chans[1] + 1))
    set_widths(drv, {ch: 0 for ch in chans})
    since = settle(drv, 3)
    for ch in channels(drv):
        check_silent(drv, pins[ch], since)
    if drv.board == "m32d":
        for ch in chans[:3]:
            assert drv.pin(pins[ch]) == (0, "in")          # back to GPIO: an input
        assert drv.pin(pins[14]) == (0, "out")             # back to the stopped motor
    else:
        for clk in ("E3", "E4", "E5", "B7"):
            assert drv.edges(clk, since) == [], clk
    assert drv.rd(rs(drv), drv.lay["servo_channels"] // 8) == bytes(drv.lay["servo_channels"] // 8)


@pytest.mark.parametrize("on", [[1], [1, 9, 17, 25], [3, 4, 12, 30]])
def test_m128s_off_channel_on_a_running_counter(drv, on):
    """docs: an off channel sharing a counter with pulsing channels sees a
    pulse of 87-125 us each frame; a counter with no channel on stays
    silent."""
    if drv.board != "m128s":
        pytest.skip("M128-S only")
    set_widths(drv, {ch: 1500 for ch in on})
    since = settle(drv)
    busy = {ch // 8 for ch in on}
    lo_c, hi_c = (us_to_cycles(u) for u in OFF_PULSE_US)
    bad = []
    for ch in range(32):
        sig = "servo%d" % ch
        if ch in on:
            check_pulses(drv, sig, 1500, since)
        elif ch // 8 in busy:
            m = drv.measure(sig, since)
            assert "high" in m and m["n"] >= 3, (sig, m)
            if not (lo_c <= m["high"][0] and m["high"][1] <= hi_c):
                bad.append("%s %.1f..%.1f us" % (sig, m["high"][0] / 7.3728, m["high"][1] / 7.3728))
            assert abs(m["period"][0] - SERVO_FRAME) <= PERIOD_TOL, (sig, m)
        else:
            check_silent(drv, sig, since)
    assert bad == [], "off channels outside %d-%d us: %s" % (OFF_PULSE_US + (", ".join(bad),))


def test_m128s_counter_clocks_meet_cd4017_timing(drv):
    """M128-S: each running counter gets nine rising clock edges a frame
    (Q1..Q8, then rest in Q9), every clock phase lasts at least 1 us (CD4017B
    at 5 V needs 0.2 us), the reset pulse at least 0.3 us and it ends before
    the first clock; the counter with no channel on is never clocked."""
    if drv.board != "m128s":
        pytest.skip("M128-S only")
    on = [3, 4, 12, 30]                       # counters 0, 1 and 3; 2 idles
    set_widths(drv, {ch: 1500 for ch in on})
    since = settle(drv)
    resets = drv.edges("E6", since)
    rises = [t for t, v in resets if v == 1]
    falls = [t for t, v in resets if v == 0]
    assert len(rises) >= 4 and len(falls) >= 4, resets
    frames = list(zip(rises, falls))[:-1]
    for clk, busy in (("E3", True), ("E4", True), ("E5", False), ("B7", True)):
        edges = drv.edges(clk, since)
        if not busy:
            assert edges == [], clk
            continue
        phases = [b[0] - a[0] for a, b in zip(edges, edges[1:])]
        assert min(phases) >= 8, (clk, min(phases))          # >= 1.085 us
        for (r_on, r_off), nxt in zip(frames, rises[1:]):
            assert r_off - r_on >= 3, (r_on, r_off)             # reset >= 0.4 us
            in_frame = [t for t, v in edges if v == 1 and r_on <= t < nxt]
            assert len(in_frame) == 9, (clk, len(in_frame))
            assert in_frame[0] > r_off, clk


def test_m32d_widths_exact_while_the_adc_converts(drv):
    """M32-D: the ADC interrupt (a conversion every 1664 cycles on port A
    line 0; one channel is the longest search for the next) never delays a
    servo edge: every other channel, on the same port and elsewhere, keeps
    its width within 1.1 us."""
    if drv.board != "m32d":
        pytest.skip("M32-D only: servo pins share port A with the ADC")
    drv.ctl.adc(0, 2500)
    drv.wr(drv.lay["adc"], b"\x05\x01")                 # AVCC, 10-bit, channel 0
    chans = range(1, drv.lay["servo_channels"])
    set_widths(drv, {ch: 1000 + 100 * (ch % 8) for ch in chans})
    since = settle(drv)
    for ch in chans:
        check_pulses(drv, drv.lay["servo_pins"][ch], 1000 + 100 * (ch % 8), since)
    got = int.from_bytes(drv.rd(drv.lay["adc"] + 1, 2), "big")   # conversions ran
    assert abs(got - 2500 * 1023 / 5000) <= 2, got
    drv.wr(drv.lay["adc"], b"\x05\x00")


# --- registers ------------------------------------------------------------------------

def test_readback_first_channel_and_rs(drv):
    n = drv.lay["servo_channels"]
    widths = {0: 0x0064, 1: 1234, 3: 3000, n - 1: 2000, n - 3: 777}
    set_widths(drv, widths)
    clamped = {ch: min(max(w, 500), 2500) for ch, w in widths.items()}
    table = b"".join(clamped.get(ch, 0).to_bytes(2, "big") for ch in range(n))
    assert drv.rd(sp(drv), 32) == table[:32]                    # first channel 0
    drv.wr(sp(drv), bytes([n - 4]))
    assert drv.rd(sp(drv), 8) == table[2 * (n - 4):]
    assert drv.rd(sp(drv), 2) == table[2 * (n - 4):2 * (n - 3)]  # each read afresh
    drv.wr(sp(drv), bytes([1]))
    assert drv.rd(sp(drv), 4) == table[2:6]
    drv.wr(sp(drv), b"\x00")
    mask = sum(1 << ch for ch in widths)
    assert drv.rd(rs(drv), n // 8) == mask.to_bytes(n // 8, "big")   # highest channel first
    drv.wr(rs(drv), b"\x00" * (n // 8))                              # accepted, no effect
    assert drv.rd(rs(drv), n // 8) == mask.to_bytes(n // 8, "big")
    since = settle(drv, 3)
    for ch, w in clamped.items():
        check_pulses(drv, drv.lay["servo_pins"][ch], w, since)


def test_rejections_leave_pulses_unchanged(drv):
    n = drv.lay["servo_channels"]
    widths = {0: 1500, 2: 700, n - 1: 2200}
    set_widths(drv, widths)
    drv.wait(2 * SERVO_FRAME + 8192)
    before = drv.rd(sp(drv), 32)
    since = drv.now()
    triple = lambda ch, w: bytes([ch, w >> 8, w & 0xFF])
    cases = [
        (triple(0, 900)[:2], BAD_LENGTH),                     # 2 bytes
        (triple(0, 900) + b"\x02", BAD_LENGTH),               # 4 bytes
        (triple(0, 900) + triple(2, 900)[:2], BAD_LENGTH),    # 5 bytes
        (b"".join(triple(ch % n, 900) for ch in range(17)), BAD_LENGTH),   # 51 bytes
        (triple(0, 900) + triple(n, 900), BAD_VALUE),         # channel out of range
        (triple(0xFF, 900), BAD_VALUE),
        (bytes([n]), BAD_VALUE),                              # first channel out of range
    ]
    for data, status in cases:
        drv.wr_refused(sp(drv), data, status)
    assert drv.rd(sp(drv), len(before)) == before
    drv.wait(4 * SERVO_FRAME)
    for ch in channels(drv):
        sig = drv.lay["servo_pins"][ch]
        if ch in widths:
            check_pulses(drv, sig, widths[ch], since)
        elif drv.board == "m32d":
            check_silent(drv, sig, since)
    # the first channel selection stayed 0
    assert drv.rd(sp(drv), 2) == widths[0].to_bytes(2, "big")


def test_m32d_servo_on_an_adc_line_is_refused(drv):
    """The whole write is refused (status 03) when one channel's pin is an
    enabled ADC channel's; nothing starts pulsing."""
    if drv.board != "m32d":
        pytest.skip("M32-D only: servo pins are port pins")
    drv.wr(drv.lay["adc"], b"\x01\x04")                 # ADC channel 2 = PA2 = servo 2
    t0 = drv.now()
    drv.wr_refused(sp(drv), bytes([0, 5, 0xDC, 2, 5, 0xDC]), PIN_BUSY)
    assert drv.rd(sp(drv), 6) == bytes(6)
    drv.wait(3 * SERVO_FRAME)
    check_silent(drv, "A0", t0)
    check_silent(drv, "A2", t0)
    assert drv.pin("A2") == (0, "in")
    # and the other way round: an ADC channel on a pulsing servo's line
    set_widths(drv, {3: 1500})
    drv.wr_refused(drv.lay["adc"], b"\x01\x0C", PIN_BUSY)
    assert drv.rd(drv.lay["adc"], 2) == b"\x01\x04"
    since = settle(drv, 3)
    check_pulses(drv, "A3", 1500, since)


def test_m32d_a_channel_turned_off_leaves_its_line_to_gpio_at_once(drv):
    """M32-D: a channel turned off is GPIO's line at once; the edges of it
    that the frame running (or the next, before the plan without it is
    taken over) still holds must not reach it: GPIO makes it an output,
    high, with the very next requests, and it stays high (the old
    schedule's fall pulled it low)."""
    if drv.board != "m32d":
        pytest.skip("the M32-D's own pins")
    pin = drv.lay["servo_pins"][0]
    port = drv.lay["gpio_ports"].index(pin[0])
    bit = bytes([1 << int(pin[1])])
    set_widths(drv, {0: 1500})
    settle(drv, 2)
    fall = drv.edges(pin, drv.now() - SERVO_FRAME)[-1]
    assert fall[1] == 0, fall
    # just after a fall (any time before the plan is taken over would do:
    # a loaded machine's simulator may have passed it)
    drv.wait(max(1, fall[0] + 2 * SERVO_FRAME + 1000 - drv.now()))
    set_widths(drv, {0: 0})
    drv.wr(drv.lay["gpio_mode"] + port, bit + bit)             # output ...
    drv.wr(drv.lay["gpio_val"] + port, bit + bit)              # ... high
    since = drv.now()
    drv.wait(3 * SERVO_FRAME)
    assert drv.edges(pin, since) == [], pin
    assert drv.pin(pin) == (1, "out"), pin
    drv.wr(drv.lay["gpio_mode"] + port, b"\x00" + bit)
