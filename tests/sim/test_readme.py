"""README's sample sessions, replayed against the boards they describe: every
`orfa> REQUEST` line and the reply printed under it, exactly. A README that
shows a reply the board does not give fails here."""

import re
from pathlib import Path
import pytest

from conftest import require_builds, require_slave, running
from orfa.sim import SimBoard

README = Path(__file__).resolve().parents[2] / "README.md"


def sessions() -> dict:
    """{section title: [(request, reply), ...]} of README's console sessions."""
    out = {}
    section = None
    lines = README.read_text().splitlines()
    for i, line in enumerate(lines):
        if line.startswith("## "):
            section = line[3:].strip()
        m = re.match(r"    orfa> (.*)$", line)
        if m:
            reply = lines[i + 1]
            assert reply.startswith("    ") and not reply.startswith("    orfa>"), reply
            out.setdefault(section, []).append((m.group(1), reply[4:]))
    return out


def replay(gw, pairs):
    got = [(req, gw.gw.request(req)) for req, _ in pairs]
    assert got == pairs


def test_readme_has_the_sessions():
    s = sessions()
    assert len(s["Two commands on a fresh machine"]) >= 8
    assert len(s["A simulated robot"]) >= 8


def test_demo_session():
    """`make demo`: an M32-D gateway with the EEPROM at A0."""
    require_builds(["m32d"])
    with running(SimBoard("m32d", eeproms=(0xA0,), trace=True)) as gw:
        replay(gw, sessions()["Two commands on a fresh machine"])


def test_robot_session():
    """`make demo-robot`: slaves M128-S at 0x10 and M32-D at 0x12, EEPROM at A0,
    the sensors (MPU-6050 D0, HMC5883L 3C, LIS3MDL 38, BMP280 EC, 24LC32 A8)."""
    require_builds(["m32d"])
    slaves = [("m128s", 0x10, require_slave("m128s", 0x10)),
              ("m32d", 0x12, require_slave("m32d", 0x12))]
    parts = [("mpu6050", 0xD0), ("hmc5883l", 0x3C), ("lis3mdl", 0x38), ("bmp280", 0xEC),
             ("24lc32", 0xA8)]
    with running(SimBoard("m32d", eeproms=(0xA0,), trace=True, slaves=slaves,
                          parts=parts)) as gw:
        replay(gw, sessions()["A simulated robot"])


@pytest.mark.parametrize("section", ["Two commands on a fresh machine", "A simulated robot"])
def test_sessions_start_on_a_prompt(section):
    assert all(req for req, _ in sessions()[section])
