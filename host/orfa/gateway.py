"""A gateway on a serial line: requests out, reply lines back.

The transport is `serial.serial_for_url(url)`, so `loop://`, `socket://`, a
pseudo-terminal path (the simulator's link) and a real port are the same.
"""

from __future__ import annotations

import math
import time
from collections import deque
from typing import Callable, Dict, FrozenSet, Iterable, List, Optional, Sequence, Union

import serial

from . import boardmap
from . import flow
from . import protocol as p
from .closing import Closing
from .errors import SerialError

#: i2cdetect's default range of 7-bit addresses (the others are reserved)
SCAN_FIRST, SCAN_LAST = 0x08, 0x77


#: Above this no port has a rate (Linux's termios2 takes 32 bits; pyserial
#: overflows on a real port and refuses on loop://).
MAX_BAUDRATE = 2 ** 31 - 1


def check_baudrate(baudrate) -> int:
    """The rate as pyserial takes it (an int above 0, or what int() makes
    one of: "460800"); else ValueError in serial.Serial's words, before a
    port is opened: a bad argument is the caller's, not the port's."""
    try:
        rate = int(baudrate)
    except (TypeError, ValueError):
        rate = 0
    if not 0 < rate <= MAX_BAUDRATE:
        raise ValueError("Not a valid baudrate: %r" % (baudrate,))
    return rate


def check_timeout(timeout) -> float:
    """Seconds to wait for a reply: a finite number, 0 or more (not None,
    which pyserial takes for "forever": every call here has a deadline);
    else ValueError in pyserial's words."""
    try:
        seconds = float(timeout)
    except (TypeError, ValueError):
        seconds = math.nan
    if isinstance(timeout, (str, bytes)) or not 0 <= seconds < math.inf:
        raise ValueError("Not a valid timeout: %r (seconds, 0 or more)" % (timeout,))
    return timeout


def open_port(url: str, baudrate: int, timeout: float) -> serial.SerialBase:
    """serial.serial_for_url, its errors as one-line SerialErrors (a bad
    baudrate or timeout a ValueError: check_baudrate, check_timeout); a
    real port in low-latency mode (low_latency)."""
    baudrate = check_baudrate(baudrate)
    timeout = check_timeout(timeout)
    try:
        port = serial.serial_for_url(url, baudrate=baudrate, timeout=timeout)
    except (serial.SerialException, OSError, ValueError) as e:
        raise SerialError("cannot open %s: %s" % (url, os_reason(e))) from e
    low_latency(port)
    return port


def low_latency(port) -> bool:
    """Ask the OS to hand received bytes over at once rather than after a
    USB-serial adapter's latency timer (16 ms on FTDI chips): pyserial's
    set_low_latency_mode(True), which Linux real ports have
    (ASYNC_LOW_LATENCY). A port without it (another OS, socket://, loop://)
    or that refuses it (a pty: no such ioctl) stays as it is, quietly.
    True if the mode was set."""
    setter = getattr(port, "set_low_latency_mode", None)
    if setter is None:
        return False
    try:
        setter(True)
    except (ValueError, OSError, serial.SerialException, NotImplementedError):
        return False
    return True


def os_reason(e: BaseException, errno: bool = True) -> str:
    """Why a port did not open, from the innermost OS error of the chain:
    "[Errno 2] No such file or directory" (errno=False: without the
    number) rather than pyserial's message that repeats the path; else the
    innermost error's own text ("invalid URL")."""
    seen = e
    while True:
        if isinstance(seen, OSError) and not isinstance(seen, serial.SerialException) \
                and seen.strerror:
            if errno and seen.errno is not None:
                return "[Errno %d] %s" % (seen.errno, seen.strerror)
            return seen.strerror
        inner = seen.__cause__ or seen.__context__
        if inner is None:
            return str(seen)
        seen = inner


Reply = Union[str, p.OrfaError]

#: A read may end this much after its deadline rather than change the
#: port's timeout for it.
_TIMEOUT_GRACE = 0.01

#: The opening sync (Gateway.sync_open): a character that no request may
#: hold and a CR end a partial line as a refused one; then two requests
#: whose replies are known.
SYNC_OPEN = b"!\r" + p.encode_request(flow.MARKER) + p.encode_request(flow.SYNC_SECOND)


def _clip(text, size: int = 60):
    """A line's start, for a one-line error message."""
    if len(text) <= size:
        return text
    return text[:size] + (b"..." if isinstance(text, bytes) else "...")


#: The status register: introspection's second, on every board (docs/registers.md).
_STATUS_REGISTER = boardmap.load(boardmap.BOARDS[0]).reg("intro", "STATUS")


class Pending:
    """Requests handed to Gateway.submit() or submit_transactions(): on
    their way to the board as the flow rule lets them; wait() for what
    run() or transactions() would have returned."""

    def __init__(self, gateway: "Gateway", lines: List[str]):
        self.gateway = gateway
        self.lines = lines
        #: the transactions' frames (submit_transactions), else None
        self.frames: Optional[List[List[p.Frame]]] = None
        self.replies: List[Optional[Reply]] = [None] * len(lines)
        #: requests still without an answer
        self.left = len(lines)

    @property
    def done(self) -> bool:
        """True once every request has its answer (wait() returns at once)."""
        return not self.left

    def wait(self):
        """Read replies until these requests have theirs (the requests
        submitted before are answered first, later ones go out meanwhile),
        then: submitted as lines, their reply texts (the first error
        raised, as run()); as transactions, each one's frame results or
        OrfaError (as transactions())."""
        if self.left:
            self.gateway._wait(self)
        if self.frames is None:
            for reply in self.replies:
                if isinstance(reply, p.OrfaError):
                    raise reply
            return list(self.replies)
        out: List[Union[List[p.FrameResult], p.OrfaError]] = []
        for frames, reply in zip(self.frames, self.replies):
            if isinstance(reply, p.OrfaError):
                out.append(reply)
                continue
            try:
                out.append(p.parse_transaction(reply, frames))
            except p.OrfaError as e:
                out.append(e)
        return out


class _Request:
    """One submitted request in the gateway's stream."""

    __slots__ = ("line", "pattern", "cost", "pending", "index")

    def __init__(self, line: str, pattern, pending: Pending, index: int):
        self.line = line
        self.pattern = pattern
        self.cost = flow.request_cost(line)
        self.pending = pending
        self.index = index

    def answer(self, reply: Reply) -> None:
        """Its reply text or error; a second answer (out of step after
        all) replaces the first."""
        if self.pending.replies[self.index] is None:
            self.pending.left -= 1
        self.pending.replies[self.index] = reply


class Gateway(Closing):
    """An ORFA gateway on one serial port; a context manager.

    autobaud=True sends the preamble of a BAUD=auto firmware (eight CRs, then
    quiet) right after opening; see preamble().

    Before the first bytes it sends, the gateway ends whatever partial line
    the board holds and drops every line up to the replies of its own
    requests (sync_open()), so the first request is answered as itself;
    sync=False leaves that out (a line that is not a board's).
    """

    def __init__(self, url: str, baudrate: int = p.DEFAULT_BAUD, timeout: float = 2.0,
                 local_address: int = p.DEFAULT_LOCAL_ADDRESS, autobaud: bool = False,
                 wait: Optional[Callable[[float], None]] = None, sync: bool = True):
        self.timeout = timeout
        self.local = local_address
        self.url = url
        self.serial = open_port(url, baudrate, timeout)
        self._boards: Dict[int, object] = {}
        #: set when the line may hold replies nobody waits for (a timeout,
        #: noise): the next run resynchronises first
        self._dirty = False
        #: False until the opening sync is done (sync_open)
        self._synced = not sync
        #: times the line was brought back in step (noise, stale lines, timeouts)
        self.resyncs = 0
        #: bytes read from the port beyond the last line taken (_read_until)
        self._rx = bytearray()
        #: the stream of submitted requests (submit()): not yet sent, and
        #: sent with their replies still to come (their characters: in_flight)
        self._unsent: deque = deque()
        self._sent: deque = deque()
        self._in_flight = 0
        #: requests answered since the first ERROR reply not yet confirmed
        #: by a marker (an ERROR may be an extra line: see _confirm)
        self._unsure: List["_Request"] = []
        if autobaud:
            self.preamble(wait)

    def preamble(self, wait: Optional[Callable[[float], None]] = None) -> None:
        """Send the autobaud preamble at the port's rate, then stay quiet
        until the firmware listens (docs/protocol.md, "Autobaud"). `wait(seconds)` passes
        that time: a simulator's simulated clock (SimBoard.wait_s); by
        default time.sleep, for a real board. Empty lines to a firmware of
        a fixed rate (no reply)."""
        self._write(p.AUTOBAUD_PREAMBLE)
        (wait or time.sleep)(p.autobaud_wait_s(self.serial.baudrate))

    # --- lifetime (a context manager: Closing) -------------------------------
    def close(self) -> None:
        self.serial.close()

    # --- lines ----------------------------------------------------------------
    def send(self, data: bytes) -> None:
        """Write raw bytes (no checks, no terminator added); the opening
        sync first if it is not done (sync_open)."""
        if not self._synced:
            self.sync_open()
        self._write(data)

    def _write(self, data: bytes) -> None:
        try:
            self.serial.write(data)
            self.serial.flush()
        except (serial.SerialException, OSError) as e:
            raise SerialError("%s: %s" % (self.url, os_reason(e))) from e

    def _read_until(self, left: float) -> bytes:
        """Bytes up to an LF, or what came within `left` seconds: the
        port's own timeout is shortened for this read when clearly less is
        left (on a real port that reconfigures it: not for every line).
        A pyserial port is read for all it holds at once (in_waiting), the
        bytes after the LF kept for the next line: pyserial's read_until
        takes one byte a call, and a USB-serial adapter hands over a
        millisecond's bytes at once (46 at 460800 baud)."""
        port = self.serial
        if not isinstance(port, serial.SerialBase):        # a wrapper, a test's fake
            return self._port_call(port.read_until, b"\n", left)
        buf = self._rx
        deadline = time.monotonic() + left
        first = True
        while b"\n" not in buf:
            waiting = self._port_waiting()
            if waiting:
                buf += self._port_call(port.read, waiting, None)
                continue
            left = deadline - time.monotonic()
            if left <= 0 and not first:
                break
            # one byte, waited for; then what came with it
            got = self._port_call(port.read, 1, max(left, 0.0))
            first = False
            if not got:
                break
            buf += got
        end = buf.find(b"\n") + 1 or len(buf)
        line = bytes(buf[:end])
        del buf[:end]
        return line

    def _port_call(self, read, arg, left: Optional[float]):
        """read(arg) on the port, its timeout shortened to `left` when
        clearly less is left (None: as it is); its errors as SerialError."""
        port = self.serial
        try:
            if left is None or not (port.timeout is None or left < port.timeout - _TIMEOUT_GRACE):
                return read(arg)
            kept = port.timeout
            port.timeout = left
            try:
                return read(arg)
            finally:
                port.timeout = kept
        except (serial.SerialException, OSError) as e:
            raise SerialError("%s: %s" % (self.url, os_reason(e))) from e

    def read_reply(self, timeout: Optional[float] = None) -> str:
        """The next reply line without its CR LF; ReplyTimeout if none comes
        within `timeout` seconds (default: the gateway's)."""
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        buf = bytearray()
        while not buf.endswith(b"\r\n"):
            left = deadline - time.monotonic()
            if left <= 0:
                raise p.ReplyTimeout("no reply line (got %r)" % _clip(bytes(buf)))
            chunk = self._read_until(left)
            buf += chunk
            if buf.endswith(b"\n") and not buf.endswith(b"\r\n"):
                raise p.ProtocolError("reply line not ended by CR LF: %r" % bytes(buf))
        return p.strip_reply(bytes(buf))

    def request(self, line: str) -> str:
        """Send one request, return its reply text (ERROR replies included);
        submitted requests still under way are answered first."""
        self._drain()
        self.send(p.encode_request(line))
        return self.read_reply()

    def pipeline(self, lines: Sequence[str]) -> List[str]:
        """run(lines), by its earlier name: the requests pipelined within the
        flow rule (it once wrote them all at once, past the rule)."""
        return self.run(lines)

    # --- batches: many requests in flight (docs/protocol.md, "Flow") -----------------
    def run(self, lines: Sequence[str]) -> List[str]:
        """Send every request, pipelined, and return their reply texts in
        order (`ERROR xx` replies included, as request() does).

        Requests go out as long as fewer than 256 characters of them are
        unanswered (flow.FLOW_WINDOW); each reply line is checked against
        its request (flow.reply_pattern). A line that cannot be a reply is
        noise: the gateway resynchronises with a `V` marker, and a request
        whose reply was lost to the noise raises ProtocolError (after the
        line is in step again). No reply in time: ReplyTimeout.
        """
        return self.submit(lines).wait()

    def transactions(self, items: Sequence[Sequence[p.Frame]]
                     ) -> List[Union[List[p.FrameResult], p.OrfaError]]:
        """Run many transactions pipelined (see run()); for each, its frame
        results or the OrfaError its reply gave (an `ERROR xx`, a reply
        lost to noise), so one refused item leaves the others' results."""
        return self.submit_transactions(items).wait()

    def submit(self, lines: Sequence[str]) -> "Pending":
        """run(lines) without waiting: the requests join the stream of
        submitted ones and go out as the flow rule lets them (some at once,
        the rest while the gateway waits for any reply); Pending.wait()
        gives what run() returns. Requests submitted before are answered
        first, in order, so a program can send its next requests while the
        board still answers the last ones (docs/python.md, "Pipelining
        across calls")."""
        lines = [p.check_request(line) for line in lines]
        patterns = []
        for line in lines:
            pattern = flow.reply_pattern(line)
            if pattern is None:
                raise ValueError("%r gets no reply (empty line or comment)" % line)
            patterns.append(pattern)
        if not self._unsent and not self._sent:
            self.in_step()
        pending = Pending(self, lines)
        self._unsent.extend(_Request(line, pattern, pending, i)
                            for i, (line, pattern) in enumerate(zip(lines, patterns)))
        self._send_what_fits()
        return pending

    def submit_transactions(self, items: Sequence[Sequence[p.Frame]]) -> "Pending":
        """transactions(items) without waiting, as submit(): Pending.wait()
        gives what transactions() returns."""
        items = [list(frames) for frames in items]
        pending = self.submit([p.format_transaction(frames) for frames in items])
        pending.frames = items
        return pending

    def _send_what_fits(self) -> None:
        """Send the submitted requests that the flow window has room for,
        in one write; room for a marker is always kept."""
        reserve = flow.request_cost(flow.MARKER)
        batch = bytearray()
        while self._unsent and \
                self._in_flight + self._unsent[0].cost + reserve < flow.FLOW_WINDOW:
            req = self._unsent.popleft()
            batch += p.encode_request(req.line)
            self._sent.append(req)
            self._in_flight += req.cost
        if batch:
            self.send(bytes(batch))

    def _wait(self, pending: "Pending") -> None:
        """Read replies (sending what the window lets out) until every
        request of `pending` has its answer; after an ERROR reply, until the
        stream is empty and a marker confirms the line (_confirm)."""
        try:
            while pending.left or (self._unsure and (self._sent or self._unsent)):
                self._step()
            if self._unsure:
                self._confirm()
        except p.ReplyTimeout as e:
            # the line is out of step (marked dirty): nothing under way will be answered
            for req in list(self._sent) + list(self._unsent):
                req.answer(e)
            self._sent.clear()
            self._unsent.clear()
            self._in_flight = 0
            self._unsure = []
            raise

    def _drain(self) -> None:
        """Wait for every submitted request's reply."""
        while self._sent or self._unsent:
            self._wait((self._unsent or self._sent)[-1].pending)

    def _step(self) -> None:
        """Send what fits, then read one line and give it to the first
        request under way; noise: resynchronise (_settle)."""
        self._send_what_fits()
        text = self._read_line()
        req = self._sent[0]
        if flow.plausible(req.pattern, text):
            self._sent.popleft()
            self._in_flight -= req.cost
            req.answer(text)
            if self._unsure or text.startswith("ERROR"):
                self._unsure.append(req)
            return
        # noise: stop sending, mark, and sort out the lines up to the marker
        self.resyncs += 1
        # the noise may be the reply an extra ERROR line displaced
        self._out_of_step(self._unsure)
        self._write(p.encode_request(flow.MARKER))
        self._settle(list(self._sent))
        self._sent.clear()
        self._in_flight = 0

    def _out_of_step(self, reqs: Sequence["_Request"]) -> None:
        for req in reqs:
            req.answer(p.ProtocolError(
                "replies out of step from %r on (an extra line on the serial "
                "line); its result is unknown" % req.line))
        self._unsure = []

    def _confirm(self) -> None:
        """After a run with an ERROR reply, the stream empty: an ERROR line
        could have been an extra line (a garbled request the board
        refused), so a `V` marker's reply must come next. If it does not, a
        line too many came somewhere from the first ERROR on, and those
        requests' results are not trusted."""
        self._write(p.encode_request(flow.MARKER))
        text = self._read_line()
        if text != flow.MARKER_REPLY:
            self.resyncs += 1
            self._until_marker(time.monotonic() + self.timeout)
            self._out_of_step(self._unsure)
        self._unsure = []

    def sync_open(self) -> int:
        """End whatever partial line the board holds (a terminal's `S AA 0`
        without its Enter, bytes of a program at another rate) and drop
        every line up to the replies of a `V` and a `C`; send() does this
        before the gateway's first bytes. The partial line is ended by a
        character no request may hold, then a CR, so the board refuses it
        (an `ERROR xx`, dropped) and never runs it; on a clean line that is
        an `ERROR 02`. The pair of replies, `V1.1` then the clock (`C` and
        four digits, never an error), is known: a partial line's one reply
        cannot be it, nor can stale replies of requests other than these.
        Everything goes in one write (a handful of characters, within the
        flow rule) and takes one round trip. ReplyTimeout if the pair does not come within
        the gateway's timeout (no board, or a line that carries lines that
        are not replies); the next send tries again. Returns the number of
        lines dropped."""
        self._write(SYNC_OPEN)
        deadline = time.monotonic() + self.timeout
        seen: List[str] = []
        try:
            while True:
                text = self._line_by(deadline, seen)
                if seen and seen[-1] == flow.MARKER_REPLY and flow.SYNC_SECOND_REPLY.match(text):
                    break
                seen.append(text)
        except p.ReplyTimeout as e:
            # a board built for another rate sees garbage and answers in it
            raise p.ReplyTimeout("%s; nothing answered the opening sync at %s baud (a gateway"
                                 " answers only at the rate it was built for, its BAUD)"
                                 % (e, self.serial.baudrate)) from None
        self._synced = True
        self._dirty = False
        return len(seen) - 1

    def resync(self) -> int:
        """Bring the line in step: send the `V` marker and drop every line
        up to its `V1.1` (the opening sync instead, if it is not done).
        Returns the number of lines dropped. ReplyTimeout if no `V1.1` comes
        within the gateway's timeout, whatever else comes."""
        self.resyncs += 1
        if not self._synced:
            return self.sync_open()
        self._write(p.encode_request(flow.MARKER))
        dropped = len(self._until_marker(time.monotonic() + self.timeout))
        self._dirty = False
        return dropped

    def in_step(self) -> None:
        """Resynchronise first if a timeout left the line out of step,
        bytes wait that nobody asked for, or the opening sync is not done
        (run() and transactions() do this on their own)."""
        if not self._synced:
            self.sync_open()
        elif self._dirty or self._waiting():
            self.resync()

    def _line_by(self, deadline: float, seen: List[str]) -> str:
        """The next line if it comes before `deadline`; else ReplyTimeout
        (the line marked out of step) that says what came instead."""
        left = deadline - time.monotonic()
        try:
            if left <= 0:
                raise p.ReplyTimeout("no reply line")
            return self._read_line(left)
        except p.ReplyTimeout:
            self._dirty = True
            if not seen:
                raise
        raise p.ReplyTimeout(
            "no V1.1 to the V marker within %g s: the line carries lines that are not"
            " replies (%d lines, the last %r)" % (self.timeout, len(seen), _clip(seen[-1])))

    def _until_marker(self, deadline: float, markers: int = 1) -> List[str]:
        """Read up to the `markers`-th `V1.1`; every line before it (other
        `V1.1`s included). ReplyTimeout at the deadline."""
        seen: List[str] = []
        while True:
            text = self._line_by(deadline, seen)
            if text == flow.MARKER_REPLY:
                markers -= 1
                if markers == 0:
                    return seen
            seen.append(text)

    def _read_line(self, timeout: Optional[float] = None) -> str:
        """The next line; a line that is not even text comes back as it was
        (repr), so it is noise to every pattern. Timeouts mark the line out
        of step."""
        try:
            return self.read_reply(timeout)
        except p.ReplyTimeout:
            self._dirty = True
            raise
        except p.ProtocolError as e:
            return "<noise: %s>" % e

    def reset_input_buffer(self) -> None:
        """Drop every byte received and not yet read as a reply: the
        port's (pyserial's reset_input_buffer) and what a read took past a
        line's end and kept for the next line."""
        self._rx.clear()
        self.serial.reset_input_buffer()

    def _waiting(self) -> int:
        """Bytes received that no line has taken yet."""
        return len(self._rx) + self._port_waiting()

    def _port_waiting(self) -> int:
        try:
            return self.serial.in_waiting
        except (AttributeError, NotImplementedError, serial.SerialException, OSError):
            return 0

    def _settle(self, waiting: List["_Request"]) -> None:
        """After noise (the marker sent): read every line up to the
        marker's reply and give them to the requests still waiting, if
        they line up; otherwise those requests lost their replies
        (ProtocolError)."""
        markers_due = 1 + sum(1 for r in waiting if r.line.strip(" ").upper().startswith("V"))
        seen = self._until_marker(time.monotonic() + self.timeout, markers_due)
        candidates = [t for t in seen if any(flow.plausible(r.pattern, t) for r in waiting)]
        # the line that was noise came in the first waiting request's place:
        # an extra line (all replies follow) or its reply garbled (one fewer)
        for lost in (0, 1):
            rest = waiting[lost:]
            if len(candidates) == len(rest) and all(
                    flow.plausible(r.pattern, t) for r, t in zip(rest, candidates)):
                for r, t in zip(rest, candidates):
                    r.answer(t)
                waiting = waiting[:lost]
                break
        for r in waiting:
            r.answer(p.ProtocolError("the reply to %r was lost to noise on the serial line"
                                     % r.line))

    # --- commands -------------------------------------------------------------
    def version(self) -> str:
        return p.parse_version(self.request(p.format_version()))

    def clear_bus(self) -> None:
        p.parse_clear(self.request(p.format_clear()))

    def local_address(self, new: Optional[int] = None) -> int:
        addr = p.parse_local_address(self.request(p.format_local_address(new)))
        self.local = addr
        return addr

    def scan(self, first: int = SCAN_FIRST, last: int = SCAN_LAST) -> List[int]:
        """The 7-bit addresses first..last that acknowledge a probe
        (`S<addr> P`, pipelined), as i2cdetect finds them."""
        addrs = list(range(first, last + 1))
        replies = self.run(["S%02XP" % (a << 1) for a in addrs])
        found = []
        for a, reply in zip(addrs, replies):
            if reply == "SWP":
                found.append(a)
            elif reply != "ERROR 06":
                raise p.ProtocolError("probe of 7-bit 0x%02X answered %r" % (a, reply))
        return found

    def clock(self, khz: Optional[int] = None) -> int:
        return p.parse_clock(self.request(p.format_clock(khz)))

    def transaction(self, frames: Sequence[p.Frame]) -> List[p.FrameResult]:
        frames = list(frames)
        line = p.format_transaction(frames)
        return p.parse_transaction(self.request(line), frames)

    def write(self, addr: int, data: Iterable[int] = b"") -> int:
        """Write data to a device; returns the number of acknowledged bytes."""
        (result,) = self.transaction([p.Write(addr, bytes(data))])
        return result.acks

    def probe(self, addr: int) -> bool:
        """True if a device acknowledges its address."""
        try:
            self.write(addr)
        except p.AddressNackError:
            return False
        return True

    def read(self, addr: int, count: int) -> bytes:
        (result,) = self.transaction([p.Read(addr, count)])
        return result.data

    # --- register semantics (docs/registers.md) ---------------------------------
    def write_register(self, addr: Optional[int], reg: int, data: Iterable[int] = b"") -> None:
        """Write data to register reg of addr (None: the gateway itself)."""
        addr = self.local if addr is None else addr
        self.transaction(p.register_write_frames(addr, reg, data))

    def read_register(self, addr: Optional[int], reg: int, count: int) -> bytes:
        """Select register reg of addr (None: the gateway itself), read count bytes."""
        addr = self.local if addr is None else addr
        results = self.transaction(p.register_read_frames(addr, reg, count))
        return results[-1].data

    def drivers(self, addr: Optional[int] = None) -> List[p.DriverRecord]:
        """The introspection records of addr (None: the gateway itself), driver 1 first."""
        addr = self.local if addr is None else addr
        (count,) = self.transaction([p.Write(addr, b"\x00\x00"),
                                     p.Read(addr, 1)])[-1].data
        records: List[p.DriverRecord] = []
        per_read = 10
        for first in range(1, count + 1, per_read):
            n = min(per_read, count + 1 - first)
            data = self.transaction([p.Write(addr, bytes([0x00, first])),
                                     p.Read(addr, 6 * n)])[-1].data
            records += p.DriverRecord.parse_many(data)
        return records

    # --- the sys driver and the status register, by address ----------------------
    # Shorthands for scripts that hold a Gateway: each is the Board's call
    # (orfa.board) for that address (None: the gateway itself).
    #: What board() makes: orfa.board.Board, which sets itself here when it
    #: is imported (the board layer sits above this one; importing orfa
    #: imports it).
    board_class: Optional[Callable[["Gateway", Optional[int]], object]] = None

    def board(self, addr: Optional[int] = None):
        """The Board at addr (None: the gateway's own drivers), kept per address."""
        key = self.local if addr is None else addr & 0xFE
        if key not in self._boards:
            self._boards[key] = self.board_class(self, None if key == self.local else key)
        return self._boards[key]

    def reset_cause(self, addr: Optional[int] = None) -> FrozenSet[str]:
        """Why addr reset since the causes were last cleared: a set of
        "power", "external", "brownout", "watchdog", "jtag"."""
        return self.board(addr).reset_cause()

    def clear_reset_cause(self, addr: Optional[int] = None,
                          causes: Optional[Iterable[str]] = None) -> None:
        """Forget the reset causes (all, or the names given)."""
        self.board(addr).clear_reset_cause(causes)

    def failsafe(self, addr: Optional[int] = None) -> int:
        """The link-loss failsafe's timeout in milliseconds (0: off)."""
        return self.board(addr).failsafe()

    def set_failsafe(self, addr: Optional[int], ms: int) -> None:
        """Motors stop and servos go limp when no request has reached addr
        for `ms` milliseconds; 0 turns it off."""
        self.board(addr).set_failsafe(ms)

    def status(self) -> int:
        """The gateway's status register (result of the last register access);
        one request, no introspection (Board.status() names the value)."""
        return self.read_register(None, _STATUS_REGISTER, 1)[0]
