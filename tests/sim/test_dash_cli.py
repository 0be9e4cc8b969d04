"""`orfa dash` as a command: a simulated robot (`--sim m32d --slave
m128s:0x10`), the URL on stdout, the snapshot and a control over HTTP,
SIGTERM (exit 0) and Ctrl-C (exit 130)."""

import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from orfa import boardmap

from conftest import require_builds, require_slave

pytest.importorskip("flask", reason="orfa dash needs Flask (pip install 'orfa[dash]')")

ROOT = Path(__file__).resolve().parents[2]
M32D, M128S = boardmap.load("m32d"), boardmap.load("m128s")
#: Wall-clock safety net for the command to start and answer.
TIMEOUT = 30


def orfa(*args):
    return [sys.executable, "-m", "orfa", "dash", "--sim", "m32d", "--slave", "m128s:0x10",
            "--listen", "127.0.0.1:0"] + list(args)


def start(*args):
    require_builds(["m32d"])
    require_slave("m128s", 0x10)
    proc = subprocess.Popen(
        orfa(*args),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT,
        env=dict(os.environ, PYTHONPATH=str(ROOT / "host")))
    url = proc.stdout.readline().strip()
    if not url.startswith("http://127.0.0.1:"):
        proc.kill()
        pytest.fail("orfa dash printed %r, stderr %r" % (url, proc.communicate()[1]),
                    pytrace=False)
    return proc, url


def get(url):
    with urllib.request.urlopen(url, timeout=TIMEOUT) as r:
        return json.load(r)


def post(url, body):
    req = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST",
                                 headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=TIMEOUT) as r:
            return r.status, json.load(r)
    except urllib.error.HTTPError as e:
        return e.code, json.load(e)


def snapshot_after(url, seq):
    """The first snapshot newer than `seq` (polled, bounded on the wall clock)."""
    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline:
        snap = get(url + "api/snapshot")
        if snap["seq"] > seq:
            return snap
        time.sleep(0.05)
    pytest.fail("no snapshot after %d" % seq, pytrace=False)


def stop(proc, sig):
    proc.send_signal(sig)
    try:
        out, err = proc.communicate(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        proc.kill()
        raise
    return proc.returncode, out, err


def test_serves_the_robot_and_ends_on_sigterm():
    proc, url = start("--interval", "0.05")
    try:
        snap = snapshot_after(url, 0)
        boards = {b["addr"]: b for b in snap["boards"]}
        assert list(boards) == ["%02X" % M32D.local_address, "10"]
        gw, slave = boards["AA"], boards["10"]
        assert (gw["board"], gw["role"], slave["board"], slave["role"]) == \
            ("m32d", "gateway", "m128s", "slave")
        assert [s["us"] for s in gw["servo"]] == [0] * M32D.servo_channels
        assert [s["us"] for s in slave["servo"]] == [0] * M128S.servo_channels
        assert gw["motor"] == [{"n": 1, "duty": 0, "direction": "stopped"},
                               {"n": 2, "duty": 0, "direction": "stopped"}]
        assert "motor" not in slave
        assert [g["port"] for g in gw["gpio"]] == list(M32D.gpio_ports)
        assert [g["port"] for g in slave["gpio"]] == list(M128S.gpio_ports)
        for b in (gw, slave):
            assert b["status"]["name"] == "OK" and b["reset_cause"] == ["power"]
            assert b["failsafe_ms"] == 0
        assert post(url + "api/10/servo", {"channel": 9, "us": 2000}) == \
            (200, {"servo": 9, "us": 2000, "board": "10"})
        done = snapshot_after(url, get(url + "api/snapshot")["seq"])
        assert done["boards"][1]["servo"][9] == {"ch": 9, "us": 2000, "deg": 75.0}
        assert post(url + "api/10/motor", {"motor": 1, "duty": 5}) == \
            (400, {"error": "motor: the board at 10 (m128s) has no motor driver"})
    finally:
        status, out, err = stop(proc, signal.SIGTERM)
    assert (status, out, err) == (0, "", "")


def test_the_page_turns_the_adc_on_and_shows_its_voltage():
    # `orfa dash --sim m32d --adc 0=2500`: a fresh board converts nothing;
    # the ADC control turns channel 0 on, and the next readings show 2.5 V
    proc, url = start("--adc", "0=2500", "--interval", "0.05")
    try:
        snap = snapshot_after(url, 0)
        assert snap["boards"][0]["adc"]["enabled"] == []
        assert post(url + "api/AA/adc", {"channels": [0], "reference": "avcc", "bits": 10}) \
            == (200, {"adc": [0], "reference": "avcc", "bits": 10, "board": "AA"})
        deadline = time.monotonic() + TIMEOUT
        while time.monotonic() < deadline:
            adc = snapshot_after(url, snap["seq"])["boards"][0]["adc"]
            if adc["volts"][0]:
                break
            time.sleep(0.05)
        assert adc["enabled"] == [0] and adc["volts"][1:] == [None] * 7
        # 2.5 V of AVCC's 5 V, within one step of 10 bits (the simulator gives 511)
        assert abs(adc["volts"][0] - 2.5) <= 0.005, adc
        # servo 0 is PA0, which the ADC now holds: the board says so
        status, body = post(url + "api/AA/servo", {"channel": 0, "us": 1500})
        assert status == 409 and "PIN_BUSY" in body["error"], body
    finally:
        status, out, err = stop(proc, signal.SIGTERM)
    assert (status, out, err) == (0, "", "")


def test_ctrl_c_exits_130():
    proc, url = start()
    snapshot_after(url, 0)
    status, out, err = stop(proc, signal.SIGINT)
    assert (status, out, err) == (130, "", "")


def test_other_devices_on_the_bus_are_listed():
    proc, url = start("--eeprom", "0xA0")
    try:
        snap = snapshot_after(url, 0)
    finally:
        stop(proc, signal.SIGTERM)
    assert [b["addr"] for b in snap["boards"]] == ["AA", "10"]
    assert snap["others"] == ["A0"]


def test_boards_named_instead_of_a_scan():
    proc, url = start("--boards", "0x10", "--eeprom", "0xA0")
    try:
        snap = snapshot_after(url, 0)
    finally:
        stop(proc, signal.SIGTERM)
    assert [b["addr"] for b in snap["boards"]] == ["AA", "10"]
    assert snap["others"] == []
    r = subprocess.run(orfa("--boards", "0xA0,0x10", "--eeprom", "0xA0"), capture_output=True,
                       text=True, cwd=ROOT, timeout=TIMEOUT,
                       env=dict(os.environ, PYTHONPATH=str(ROOT / "host")))
    assert (r.returncode, r.stdout, r.stderr) == (
        1, "", "orfa: 0xA0 is no ORFA board: its introspection matches no board map\n")


def test_a_port_that_does_not_open():
    r = subprocess.run([sys.executable, "-m", "orfa", "dash", "--port", "/dev/orfa-none"],
                       capture_output=True, text=True, cwd=ROOT, timeout=TIMEOUT,
                       env=dict(os.environ, PYTHONPATH=str(ROOT / "host")))
    assert (r.returncode, r.stdout) == (2, "")
    assert r.stderr == "orfa: cannot open /dev/orfa-none: No such file or directory\n"


def test_a_busy_listen_address_is_one_line():
    require_builds(["m32d"])
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        r = subprocess.run([sys.executable, "-m", "orfa", "dash", "--sim", "m32d", "--no-scan",
                            "--listen", "127.0.0.1:%d" % port],
                           capture_output=True, text=True, cwd=ROOT, timeout=TIMEOUT,
                           env=dict(os.environ, PYTHONPATH=str(ROOT / "host")))
    assert (r.returncode, r.stdout) == (2, "")
    assert r.stderr == "orfa: cannot listen on 127.0.0.1:%d: Address already in use\n" % port
