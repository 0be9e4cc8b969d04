"""`orfa console`: a line console on the gateway, as a terminal program is.

Each line goes to the board as it is and the board's reply is printed, so
the console answers what the board answers: a line over 128 characters gets
the board's `ERROR 04`, a comment line (`#` first) of any length is sent and
gets no reply, an empty line is not sent. A CR inside an input line ends a
request, as it does on the board, so each request gets its own reply shown.
An `ERROR` reply is explained on stderr as `orfa request` explains it.
`help` and `?` are answered here (HELP), not sent. Only a line that is not
ASCII is refused on the host (`host: ...`): the protocol is ASCII text.
"""

from __future__ import annotations

import os
import re
import sys
from typing import Callable, List, Optional, TextIO

from .. import protocol as p
from .common import command, connect, explain

HISTORY_ENV = "ORFA_HISTORY"
HISTORY_FILE = "~/.orfa_history"
HISTORY_LENGTH = 1000
PROMPT = "orfa> "


#: What `help` and `?` print (the board would answer them ERROR 02).
HELP = """\
Requests (docs/protocol.md), one a line; the board's reply is printed:
  V                      protocol version: V1.1
  L  /  L<addr>          the gateway's own bus address: LAA
  C  /  C<kHz>           the I2C clock in kHz, 4 hex digits: C0063
  X                      clear a stuck I2C bus
  S <addr> <bytes> P     I2C write:  S A0 10 41 42 P      -> SWAAAP
  S <addr> <reg> S <addr+1> <count> P
                         I2C read:   S A0 10 S A1 02 P    -> SWASR4142P
  # ...                  a comment: sent, no reply
Bytes are hex; addresses are 8-bit (bit 0: 1 reads), the gateway's own is AA.
An ERROR reply's meaning follows it (orfa: ...). Ctrl-D or Ctrl-C ends."""

#: The lines the console answers itself.
HELP_WORDS = ("help", "?")

#: Where the board ends a request: LF or CR (CR LF: a request, then an empty line).
_LINE_END = re.compile(r"\r\n|\r|\n")


def requests_of(line: str) -> List[str]:
    """The requests an input line holds: a CR inside it ends one, as on
    the board (`V\rS 42 P` is two requests, each with its reply)."""
    return _LINE_END.split(line)


def expects_reply(line: str) -> bool:
    """Whether the gateway answers this line (empty and comment lines: no)."""
    return bool(line.strip(" ")) and not line.startswith("#")


def exchange(gw, line: str) -> Optional[str]:
    """Send one console line as it is; its reply, None when the board sends
    none (comment or empty line), or a `host: ...` line when the host
    cannot send it."""
    try:
        if not expects_reply(line):
            if line.strip(" "):              # a comment: the board drops it too
                gw.send(line.encode("ascii", "replace") + p.REQUEST_TERMINATOR.encode())
            return None
        try:
            data = line.encode("ascii")
        except UnicodeEncodeError:
            return "host: a request is ASCII text"
        # the first send also brings the line in step (a board silent or
        # talking nonsense says so here, in time, and the console goes on)
        gw.send(data + p.REQUEST_TERMINATOR.encode())
        return gw.read_reply()
    except p.ReplyTimeout as exc:
        return "host: %s" % exc


def terminal(gw, stdin: TextIO, stdout: TextIO,
             read_line: Optional[Callable[[], Optional[str]]] = None,
             stderr: Optional[TextIO] = None) -> int:
    """Each line of stdin (or of read_line(), None at the end) a request,
    its reply printed (an ERROR's meaning on stderr)."""
    stderr = stderr or sys.stderr
    if read_line is None:
        def read_line() -> Optional[str]:
            line = stdin.readline()
            return line.rstrip("\r\n") if line else None
    while True:
        line = read_line()
        if line is None:
            return 0
        for request in requests_of(line):
            if request.strip(" ").lower() in HELP_WORDS:
                stdout.write(HELP + "\n")
                stdout.flush()
                continue
            reply = exchange(gw, request)
            if reply is None:
                continue
            stdout.write(reply + "\n")
            stdout.flush()
            if reply.startswith("ERROR"):
                try:
                    p.check_error(reply)
                except p.OrfaError as exc:      # as `orfa request` explains it
                    stderr.write("orfa: %s: %s\n" % (request, explain(exc)))
                    stderr.flush()


def readline_input() -> Callable[[], Optional[str]]:
    """Lines from the keyboard with readline's editing and a history file
    ($ORFA_HISTORY, default ~/.orfa_history) kept across sessions."""
    import atexit
    try:
        import readline
    except ImportError:                      # no readline (Windows): plain input
        readline = None
    if readline is not None:
        path = os.path.expanduser(os.environ.get(HISTORY_ENV) or HISTORY_FILE)
        try:
            readline.read_history_file(path)
        except OSError:
            pass
        readline.set_history_length(HISTORY_LENGTH)

        def save() -> None:
            try:
                readline.write_history_file(path)
            except OSError:
                pass
        atexit.register(save)

    def read_line() -> Optional[str]:
        try:
            return input(PROMPT)
        except EOFError:
            print()
            return None
        except KeyboardInterrupt:
            print()
            return None
    return read_line


def run_console(gw) -> int:
    """The console on stdin/stdout: with readline when stdin is a terminal."""
    read_line = readline_input() if sys.stdin.isatty() else None
    return terminal(gw, sys.stdin, sys.stdout, read_line)


def cmd_console(args) -> int:
    """a line console: requests in, replies out

    Each line is a request (docs/protocol.md), sent as typed; the board's
    reply is printed, and an ERROR's meaning on stderr as `orfa request`
    prints it. `help` or `?` lists the requests. On a terminal: line
    editing and history (readline; the history file is ${HISTORY_ENV} or
    {HISTORY_FILE}). A CR inside a line ends a request, as on the board. A
    line over 128 characters gets the board's ERROR 04; comment lines (#
    first) of any length are sent and get no reply. Ends at end of input
    (Ctrl-D) or Ctrl-C, exit status 0; a serial failure ends it with one
    line, exit status 1.

    example: orfa --sim m32d --eeprom 0xA0 console
    """
    with connect(args) as gw:
        return run_console(gw)


def add_parsers(sub, common) -> None:
    command(sub, [common], cmd_console, HISTORY_ENV=HISTORY_ENV, HISTORY_FILE=HISTORY_FILE)
