"""`orfa dash`: a live web page of one board or a robot (docs/dashboard.md).

    live.py     the boards on one Gateway: discovery, the poller thread, the
                snapshots it publishes, the controls (no web here)
    snapshot.py one board's state read with the typed API, as plain JSON data
    web.py      the Flask app: the page, the SSE stream, the control endpoints
    static/     the page (HTML, CSS, plain JS; nothing fetched from elsewhere)

Only web.py needs Flask (the extra `orfa[dash]`).
"""
