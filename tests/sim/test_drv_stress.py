"""Everything at once (docs/registers.md, "Reliability", with the drivers
busy): servos pulsing, the ADC converting, the motors running (M32-D), while
lines of garbage and valid requests stream in at line rate. The board answers every line with one
reply, never resets, and afterwards every driver is exactly where the valid
requests left it: widths read back and measured on the pins, ADC values of
the injected voltages, motor duty.
"""

import random

from test_drv_servo import check_pulses, settle

#: Garbage is drawn from these bytes: never a line end, never `#` first (a
#: comment gets no reply), and no `A`, `C`, `L` or `X`, so that no garbage
#: line is a request to the board's own address (AA) or changes the bus
#: clock or the local address: what the garbage does stays out of the
#: drivers' state, whatever it parses to.
GARBAGE = (b"SGPVZ0123456789BDEFbdef S P %&!?*\x00\x01\x7f\x80\xfe\xff\t"
           b"SSS  PPP 99 EE")
MV = {0: 1000, 1: 2500, 2: 4000, 3: 333}


def layout(drv):
    """(servo channels used, ADC channel mask): apart on the M32-D's port A."""
    if drv.board == "m32d":
        return list(range(4, 14)), 0x0F            # servos PA4.., ADC PA0-PA3
    return list(range(drv.lay["servo_channels"])), 0x0F


def servo_write(drv, widths):
    sp = drv.lay["servo"] + 1
    body = "".join("%02X%04X" % (ch, us) for ch, us in widths.items())
    return "S%s%02X%sP" % (drv.wa, sp, body), b"SW" + b"A" * (1 + 3 * len(widths)) + b"P\r\n"


def garbage(rng):
    line = bytes(rng.choice(GARBAGE) for _ in range(rng.randint(1, 150)))
    if line[:1] == b"#":
        line = b"%" + line[1:]
    return line


def test_garbage_and_requests_with_every_driver_busy(drv):
    rng = random.Random(20261122)
    chans, adc_mask = layout(drv)
    for ch, mv in MV.items():
        drv.ctl.adc(ch, mv)
    drv.wr(drv.lay["adc"], bytes([0x05, adc_mask]))           # AVCC, 10-bit
    if drv.lay["motor"] is not None:
        drv.wr(drv.lay["motor"], bytes([64, 200, 1, 0]))
    widths = {ch: 1000 + 37 * ch for ch in chans}
    for i in range(0, len(chans), 16):
        drv.wr(drv.lay["servo"] + 1, b"".join(
            bytes([ch, widths[ch] >> 8, widths[ch] & 0xFF]) for ch in chans[i:i + 16]))

    mark = drv.mark()
    lines = 0
    for _ in range(60):
        # one window of at most ~250 characters: lines and their replies
        chunk, expected = [], []
        while sum(len(c) + 1 for c in chunk) < 200:
            kind = rng.random()
            if kind < 0.45:
                chunk.append(garbage(rng))
                expected.append(None)                      # some reply line
            elif kind < 0.7:
                new = {ch: rng.randint(500, 2500) for ch in rng.sample(chans, rng.randint(1, 3))}
                req, reply = servo_write(drv, new)
                widths.update(new)
                chunk.append(req.encode())
                expected.append(reply)
            elif kind < 0.85:
                chunk.append(drv.req("S AA %02X S AB 08 P" % (drv.lay["adc"] + 1)).encode())
                expected.append(None)
            else:
                chunk.append(b"V")
                expected.append(b"V1.1\r\n")
        drv.gw.send(b"".join(c + b"\n" for c in chunk))
        got = drv.read_lines(len(chunk))
        replies = [l + b"\n" for l in got.split(b"\n") if l]
        assert len(replies) == len(chunk), (len(replies), len(chunk), got[-200:])
        for line, want, reply in zip(chunk, expected, replies):
            assert reply.endswith(b"\r\n"), (line, reply)
            if want is not None:
                assert reply == want, (line, reply)
            elif line.startswith(drv.req("S AA").encode()):
                assert reply.startswith(b"SWASR") and len(reply) == 5 + 16 + 3, (line, reply)
        lines += len(chunk)
    assert drv.events(mark, ["reset"]) == []
    assert lines > 300

    # every driver where the valid requests left it
    sp = drv.lay["servo"] + 1
    for first in range(0, drv.lay["servo_channels"], 16):
        drv.wr(sp, bytes([first]))
        got = drv.rd(sp, 32)
        for k in range(16):
            ch = first + k
            assert int.from_bytes(got[2 * k:2 * k + 2], "big") == widths.get(ch, 0), ch
    drv.wr(sp, b"\x00")
    since = settle(drv)
    for ch in chans:
        check_pulses(drv, drv.lay["servo_pins"][ch], widths[ch], since)
    values = drv.rd(drv.lay["adc"] + 1, 8)
    for ch, mv in MV.items():
        code = int.from_bytes(values[2 * ch:2 * ch + 2], "big")
        assert abs(code - mv * 1023 / 5000) <= 2, (ch, code)
    if drv.lay["motor"] is not None:
        for pin, pwm in (("D5", 64), ("D4", 200)):
            m = drv.measure(pin, since)
            assert abs(m["high"][0] / 368 - pwm / 255) <= 1 / 368, (pin, m)
        assert drv.pin("B0") == (1, "out") and drv.pin("B1") == (0, "out")
