"""`orfa dash`: serve the live dashboard of the board or robot on the
connection (orfa.dash) until Ctrl-C or SIGTERM."""

from __future__ import annotations

import argparse
import importlib.util
import logging
import signal

from .common import UsageError, add_sim_devices, address, arg, command, connect, number

#: The address the page is served on unless --listen says otherwise.
DEFAULT_LISTEN = ("127.0.0.1", 8000)
FLASK_HINT = "orfa dash needs Flask: pip install 'orfa[dash]'"


def listen_spec(text: str):
    """`HOST:PORT`, `:PORT` (127.0.0.1) or `PORT` -> (host, port); port 0:
    a free one."""
    host, sep, port = text.rpartition(":")
    if not sep:
        host = ""
    host = host[1:-1] if host.startswith("[") and host.endswith("]") else host
    try:
        value = int(port, 10)
    except ValueError:
        value = -1
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(
            "%r: HOST:PORT like 127.0.0.1:8000 (port 0..65535, 0: a free one)" % text)
    return (host or DEFAULT_LISTEN[0], value)


def address_list(text: str):
    """`0x10,0x12` -> [0x10, 0x12] (checked as addresses once --7bit is known)."""
    return [number(part) for part in text.split(",")]


def seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = 0.0
    if not 0.01 <= value <= 3600:
        raise argparse.ArgumentTypeError("%r: seconds, 0.01..3600 (0.2)" % text)
    return value


class _Stop(BaseException):
    """A signal to stop serving (werkzeug's serve_forever swallows
    KeyboardInterrupt, so Ctrl-C comes as this too): the exit status. A
    BaseException, as KeyboardInterrupt is, so that no `except Exception`
    (the poller's, socketserver's) takes it for an error."""

    def __init__(self, status: int):
        super().__init__(status)
        self.status = status


def _stop_with(status: int):
    def handler(*_):
        raise _Stop(status)
    return handler


def cmd_dash(args) -> int:
    """a live web page of the board or robot

    Serve a local web page of the gateway's board and the ORFA slave boards
    on its bus: servo widths and angles, motor duty and direction, ADC
    volts, GPIO levels and directions, status, reset cause and failsafe,
    read every --interval and pushed to the page, with controls for servos,
    motors, GPIO lines and the ADC. Prints the page's URL, serves until
    Ctrl-C (exit 130) or SIGTERM (exit 0). Needs Flask (pip install
    'orfa[dash]'). docs/dashboard.md.

    example: orfa dash --sim m32d --slave m128s:0x10; orfa dash --port
    /dev/ttyUSB0 --listen 127.0.0.1:8080
    """
    if importlib.util.find_spec("flask") is None:
        raise UsageError(FLASK_HINT)
    if args.addr is not None:
        raise UsageError("dash shows every board on the bus: --addr does not apply")
    from ..dash.live import Dashboard
    from ..dash.web import Server
    host, port = args.listen
    slaves = [] if args.no_scan else None
    if args.boards is not None:
        slaves = [address(args, a, "--boards") for a in args.boards]
    # from here on SIGTERM and Ctrl-C stop the command cleanly, the
    # simulated board of --sim too (while the boards are being found as well)
    previous = {sig: signal.signal(sig, _stop_with(status))
                for sig, status in ((signal.SIGTERM, 0), (signal.SIGINT, 130))}
    try:
        with connect(args) as gw:
            dash = Dashboard(gw, interval=args.interval, slaves=slaves)
            dash.discover()
            try:
                server = Server(dash, host, port)
            except OSError as exc:
                raise UsageError("cannot listen on %s:%d: %s"
                                 % (host, port, exc.strerror or exc)) from None
            # the requests' log lines would bury the terminal
            logging.getLogger("werkzeug").setLevel(logging.ERROR)
            try:
                dash.start()
                print(server.url, flush=True)
                server.serve_forever()
            finally:
                dash.close()
                server.httpd.server_close()
    except _Stop as stop:
        return stop.status
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return 0


def add_parsers(sub, common) -> None:
    cmd = command(sub, [common], cmd_dash,
                  arg("--listen", type=listen_spec, default=DEFAULT_LISTEN,
                      metavar="HOST:PORT",
                      help="where to serve the page (default 127.0.0.1:8000; port 0: a"
                           " free one). Anyone who reaches it can move the motors"),
                  arg("--interval", type=seconds, default=0.2, metavar="S",
                      help="seconds between two readings of the boards (default 0.2)"))
    which = cmd.add_mutually_exclusive_group()
    which.add_argument("--boards", type=address_list, metavar="ADDR[,ADDR...]",
                       help="the slave boards to show, by bus address, instead of those a"
                            " scan of the bus finds (finding them asks every device that"
                            " answers for its introspection: a write of 00 00)")
    which.add_argument("--no-scan", action="store_true",
                       help="the gateway's own board only: do not look for slaves")
    add_sim_devices(cmd.add_argument_group("devices of the --sim board"), suppress=True)

