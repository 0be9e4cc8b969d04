"""gateway.py against pyserial's loop:// and a fake gateway on socket://."""

import socket
import threading

import pytest

from orfa import protocol as p
from orfa.gateway import Gateway


class FakeGateway:
    """A TCP server answering each request line (ended by LF or CR, empty
    lines skipped, as the firmware does) from a table (default ERROR 02)."""

    def __init__(self, answers):
        self.answers = answers
        self.requests = []
        self.server = socket.socket()
        self.server.bind(("127.0.0.1", 0))
        self.server.listen(1)
        self.url = "socket://127.0.0.1:%d" % self.server.getsockname()[1]
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        conn, _ = self.server.accept()
        with conn:
            buf = b""
            while True:
                data = conn.recv(4096)
                if not data:
                    return
                buf += data.replace(b"\r", b"\n")
                while b"\n" in buf:
                    line, buf = buf.split(b"\n", 1)
                    text = line.decode()
                    if not text:
                        continue
                    self.requests.append(text)
                    conn.sendall(self.answers.get(text, b"ERROR 02") + b"\r\n")

    def close(self):
        self.server.close()


#: What a gateway sends before its first request (Gateway.sync_open): a
#: character no request holds and a CR end a partial line, then V and C.
SYNC = ["!", "V", "C"]


@pytest.fixture
def fake():
    answers = {
        "V": b"V1.1", "X": b"X", "L": b"LAA", "L20": b"L20", "C": b"C0063",
        "C0190": b"C0170", "SA0P": b"SWP", "SA2P": b"ERROR 06",
        "SA01011P": b"SWAAP", "SA010SA102P": b"SWASR1122P", "SA103P": b"SR010203P",
        "SAA0000SAB01P": b"SWAASR02P",
        "SAA0001SAB0CP": b"SWAASR000001000002002001000204P",
        "SAA01SAB01P": b"SWASR00P", "SAAFF00P": b"ERROR 07",
        "SA0": b"ERROR 05",
    }
    f = FakeGateway(answers)
    yield f
    f.close()


def test_commands(fake):
    with Gateway(fake.url, timeout=2) as gw:
        assert gw.version() == "1.1"
        assert gw.clear_bus() is None
        assert gw.local_address() == 0xAA
        assert gw.local_address(0x20) == 0x20
        assert gw.clock() == 0x63
        assert gw.clock(0x190) == 0x170
        assert gw.probe(0xA0) is True
        assert gw.probe(0xA2) is False
        assert gw.write(0xA0, [0x10, 0x11]) == 2
        assert gw.read(0xA1, 3) == b"\x01\x02\x03"
        assert gw.read_register(0xA0, 0x10, 2) == b"\x11\x22"
        assert gw.request("SA0") == "ERROR 05"
    assert fake.requests == SYNC + ["V", "X", "L", "L20", "C", "C0190", "SA0P", "SA2P",
                                    "SA01011P", "SA103P", "SA010SA102P", "SA0"]


def test_register_helpers_use_the_local_address(fake):
    with Gateway(fake.url) as gw:
        assert gw.status() == 0
        recs = gw.drivers()
        assert [r.uid for r in recs] == [0x0000, 0x0020]
        with pytest.raises(p.DataNackError) as exc:
            gw.write_register(None, 0xFF, [0x00])
        assert exc.value.code == 7
    assert fake.requests == SYNC + ["SAA01SAB01P", "SAA0000SAB01P", "SAA0001SAB0CP",
                                    "SAAFF00P"]


def test_errors_raise(fake):
    with Gateway(fake.url) as gw:
        with pytest.raises(p.AddressNackError):
            gw.write(0xA2)
        with pytest.raises(p.UnknownCommandError):
            gw.clock(5)                      # the fake answers ERROR 02
        with pytest.raises(p.LimitError):
            gw.request("V" * 129)
        with pytest.raises(p.LimitError):
            gw.read(0xA0, 63)
    assert "V" * 129 not in fake.requests


def test_loop_reply_lines():
    with Gateway("loop://", timeout=0.3, sync=False) as gw:
        gw.send(b"V1.1\r\nLAA\r\n")
        assert gw.read_reply() == "V1.1"
        assert gw.read_reply() == "LAA"
        with pytest.raises(p.ReplyTimeout):
            gw.read_reply()
        gw.send(b"SWP\n")
        with pytest.raises(p.ProtocolError):
            gw.read_reply()


def test_lines_that_came_together_are_read_at_once(monkeypatch):
    """What the port holds is taken in one read (a USB-serial adapter hands
    over a millisecond's bytes at once), the bytes after a line kept for the
    next one and counted as waiting; a partial line times out."""
    with Gateway("loop://", timeout=0.3, sync=False) as gw:
        reads = []
        read = gw.serial.read
        monkeypatch.setattr(gw.serial, "read", lambda n=1: reads.append(n) or read(n))
        gw.send(b"SR" + b"41" * 60 + b"P\r\nV1.1\r\nERR")
        assert gw.read_reply() == "SR" + "41" * 60 + "P"
        assert reads == [len("SR" + "41" * 60 + "P\r\nV1.1\r\nERR")]
        assert gw._waiting() == len("V1.1\r\nERR")
        assert gw.read_reply() == "V1.1" and len(reads) == 1
        with pytest.raises(p.ReplyTimeout, match="ERR"):
            gw.read_reply(timeout=0.05)


def test_pipeline_is_run(fake):
    """Replies in order, ERROR replies as text; after an ERROR reply a marker
    checks that no extra line took a request's place (Gateway.run)."""
    with Gateway(fake.url) as gw:
        assert gw.pipeline(["V", "L", "SA2P", "C"]) == ["V1.1", "LAA", "ERROR 06", "C0063"]
    assert fake.requests == SYNC + ["V", "L", "SA2P", "C", "V"]
