"""The dashboard's Flask app (docs/dashboard.md):

    GET  /                 the page (static/index.html; its JS and CSS beside it)
    GET  /events           Server-Sent Events: every snapshot as JSON (`data:`)
    GET  /api/snapshot     the latest snapshot, once
    POST /api/<addr>/servo {"channel": 3, "us": 1700} or {"channel": 3, "angle": 30}
    POST /api/<addr>/motor {"motor": 1, "duty": -128}
    POST /api/<addr>/gpio  {"port": "B", "bit": 2, "level": 1, "output": true}
    POST /api/<addr>/adc   {"channels": [0, 1], "reference": "avcc", "bits": 10}

A control answers 200 with what it set, or {"error": "..."} with 400 (a bad
request), 404 (no such board), 409 (the board refused or a line is held)
or 503 (the serial line failed). serve() runs it on werkzeug's threaded
server, so streams and controls run side by side.
"""

from __future__ import annotations

import json
import queue
import socket
import threading
from typing import Iterator

from flask import Flask, Response, jsonify, request
from werkzeug.serving import make_server, select_address_family

from .. import protocol as p
from ..errors import SerialError
from .live import ControlError, Dashboard, NotFound, Refused, explain

#: Seconds between SSE comments while no snapshot comes (a stream to a
#: browser that went away ends at the next write).
KEEPALIVE_S = 10.0


def _hosts(listen: str):
    """The names a browser may use for this server (the Host header): the
    address it listens on and the loopback names; None (any) when it listens
    on every interface. A page of another site that rebinds its own name to
    127.0.0.1 (DNS rebinding) is not among them, so it cannot move a motor."""
    if listen in ("", "0.0.0.0", "::"):
        return None
    return {listen.lower(), "localhost", "127.0.0.1", "::1"}


def _host_name(header: str) -> str:
    """`127.0.0.1:8000` -> `127.0.0.1`; `[::1]:8000` -> `::1`."""
    if header.startswith("["):
        return header[1:].partition("]")[0].lower()
    return header.rpartition(":")[0].lower() if ":" in header else header.lower()


def create_app(dash: Dashboard) -> Flask:
    app = Flask(__name__, static_folder="static", static_url_path="/static")
    app.config["ORFA_DASH"] = dash

    @app.before_request
    def known_host():
        allowed = app.config.get("ORFA_HOSTS")
        if allowed is not None and _host_name(request.host) not in allowed:
            return _error("%s is not a name this dashboard is served under (%s)"
                          % (request.host, ", ".join(sorted(allowed))), 403)
        return None

    @app.get("/")
    def index():
        return app.send_static_file("index.html")

    @app.get("/api/snapshot")
    def latest():
        snap = dash.latest()
        if snap is None:
            return _error("no snapshot yet", 503)
        return jsonify(snap)

    @app.get("/events")
    def events():
        return Response(_stream(dash), mimetype="text/event-stream",
                        headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})

    @app.post("/api/<addr>/<kind>")
    def control(addr: str, kind: str):
        try:
            body = request.get_json(silent=True)
        except RecursionError:             # nested deeper than the parser goes
            return _error("%s: the body is nested too deep to be a control" % kind, 400)
        if body is None:
            return _error("%s: the body must be JSON (Content-Type: application/json)"
                          % kind, 400)
        try:
            return jsonify(dash.control(addr, kind, body))
        except NotFound as exc:
            return _error(str(exc), 404)
        except ControlError as exc:
            return _error(str(exc), 400)
        except ValueError as exc:          # a client's own check (orfa.clients)
            return _error("%s: %s" % (kind, exc), 400)
        except Refused as exc:
            return _error(str(exc), 409)
        except (p.ReplyTimeout, SerialError, OSError) as exc:
            # before OrfaError: SerialError is one, but no board refused anything
            return _error("the serial line: %s" % explain(exc), 503)
        except p.OrfaError as exc:
            return _error(explain(exc), 409)

    @app.errorhandler(404)
    def not_found(exc):
        return _error("no such page: %s" % request.path, 404)

    @app.errorhandler(405)
    def not_allowed(exc):
        return _error("%s is not allowed on %s" % (request.method, request.path), 405)

    @app.errorhandler(Exception)
    def failed(exc):
        # the page gets one line, never a traceback
        code = getattr(exc, "code", None)
        if not isinstance(code, int) or not 400 <= code <= 599:
            code = 500
        return _error("%s: %s" % (type(exc).__name__, exc), code)

    return app


def _error(text: str, status: int):
    response = jsonify({"error": text})
    response.status_code = status
    return response


def _stream(dash: Dashboard) -> Iterator[str]:
    q = dash.subscribe()
    try:
        yield "retry: 1000\n\n"
        while True:
            try:
                snap = q.get(timeout=KEEPALIVE_S)
            except queue.Empty:
                yield ": keepalive\n\n"
                continue
            if snap is None:               # the dashboard closed
                return
            yield "event: snapshot\ndata: %s\n\n" % json.dumps(snap, separators=(",", ":"))
    finally:
        dash.unsubscribe(q)


class Server:
    """The app on werkzeug's threaded server at host:port (0: a free port);
    .url, .serve_forever() or .start() on a thread, .shutdown()."""

    def __init__(self, dash: Dashboard, host: str = "127.0.0.1", port: int = 8000):
        self.dash = dash
        self.app = create_app(dash)
        # bound here, so a busy port or an unknown host is an OSError for
        # the caller (werkzeug's own binding prints and exits instead)
        sock = socket.socket(select_address_family(host, port), socket.SOCK_STREAM)
        try:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.bind((host, port))
            sock.listen(128)
            self.httpd = make_server(host, port, self.app, threaded=True, fd=sock.fileno())
        finally:
            sock.close()                   # the server holds a duplicate
        self.app.config["ORFA_HOSTS"] = _hosts(host)
        self.host, self.port = host, self.httpd.port
        self._thread = None

    @property
    def url(self) -> str:
        host = "[%s]" % self.host if ":" in self.host else self.host
        return "http://%s:%d/" % (host, self.port)

    def serve_forever(self) -> None:
        self.httpd.serve_forever()

    def start(self) -> "Server":
        self._thread = threading.Thread(target=self.serve_forever, name="orfa-dash-http",
                                        daemon=True)
        self._thread.start()
        return self

    def shutdown(self) -> None:
        """End the streams, stop serving (from another thread than serve_forever's)."""
        self.dash.close()
        if self._thread is not None:
            self.httpd.shutdown()
            self._thread.join(timeout=10)
        self.httpd.server_close()

