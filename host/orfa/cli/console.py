"""`orfa console`: a line console on the gateway, as a terminal program is.

Each line goes to the board as it is and the board's reply is printed, so
the console answers what the board answers: a line over 128 characters gets
the board's `ERROR 04`, a comment line (`#` first) of any length is sent and
gets no reply, an empty line is not sent. Only a line that is not ASCII is
refused on the host (`host: ...`): the protocol is ASCII text.
"""

from __future__ import annotations

import os
import sys
from typing import Callable, Optional, TextIO

from .. import protocol as p
from .common import connect

HISTORY_ENV = "ORFA_HISTORY"
HISTORY_FILE = "~/.orfa_history"
HISTORY_LENGTH = 1000
PROMPT = "orfa> "


def expects_reply(line: str) -> bool:
    """Whether the gateway answers this line (empty and comment lines: no)."""
    return bool(line.strip(" ")) and not line.startswith("#")


def exchange(gw, line: str) -> Optional[str]:
    """Send one console line as it is; its reply, None when the board sends
    none (comment or empty line), or a `host: ...` line when the host
    cannot send it."""
    if not expects_reply(line):
        if line.strip(" "):                  # a comment: the board drops it too
            gw.send(line.encode("ascii", "replace") + p.REQUEST_TERMINATOR.encode())
        return None
    try:
        data = line.encode("ascii")
    except UnicodeEncodeError:
        return "host: a request is ASCII text"
    gw.send(data + p.REQUEST_TERMINATOR.encode())
    try:
        return gw.read_reply()
    except p.ReplyTimeout as exc:
        return "host: %s" % exc


def terminal(gw, stdin: TextIO, stdout: TextIO,
             read_line: Optional[Callable[[], Optional[str]]] = None) -> int:
    """Each line of stdin (or of read_line(), None at the end) a request,
    its reply printed."""
    if read_line is None:
        def read_line() -> Optional[str]:
            line = stdin.readline()
            return line.rstrip("\r\n") if line else None
    while True:
        line = read_line()
        if line is None:
            return 0
        reply = exchange(gw, line)
        if reply is not None:
            stdout.write(reply + "\n")
            stdout.flush()


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
    with connect(args) as gw:
        return run_console(gw)


def add_parsers(sub, common) -> None:
    cmd = sub.add_parser(
        "console", parents=[common], help="a line console: requests in, replies out",
        description="Each line is a request (docs/protocol.md), sent as typed; the"
                    " board's reply is printed. On a terminal: line editing and"
                    " history (readline; the history file is $%s or %s). A line"
                    " over 128 characters gets the board's ERROR 04; comment lines"
                    " (# first) of any length are sent and get no reply. Ends at"
                    " end of input (Ctrl-D) or Ctrl-C, exit status 0; a serial"
                    " failure ends it with one line, exit status 1."
                    % (HISTORY_ENV, HISTORY_FILE),
        epilog="example: orfa --sim m32d --eeprom 0xA0 console")
    cmd.set_defaults(func=cmd_console)
