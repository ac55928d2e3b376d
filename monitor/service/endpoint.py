"""The daemon's one HTTP endpoint (``http.listen``, loopback by default): metrics, health, the report.

    GET /           what is served here, as a short text
    GET /metrics    Prometheus text format, or OpenMetrics when the Accept header asks for it (negotiated as
                    prometheus-client's own handler does: :mod:`monitor.service.outputs.metrics`)
    GET /healthz    200 {"status": "ok", ...} or 503 {"status": "unhealthy", "problems": [...]}
    GET /report/    the HTML report, read-only (files under ``report_dir``; no listings, no dotfiles such as
                    the temporary ``.name.part`` of a file being rewritten, nothing outside)

Only GET and HEAD (any other method is 405 with ``Allow: GET, HEAD``); any other path is 404. A stdlib
threading server on its own daemon thread: a slow client cannot hold up the scheduler, and a scrape opens
its own connection to the store.
"""

from __future__ import annotations

import json
import logging
import os
import socket
import threading
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any, Protocol

from prometheus_client import CollectorRegistry
from prometheus_client.exposition import choose_encoder

LOG = logging.getLogger(__name__)
INDEX = (
    b"crisgeo-monitor\n"
    b"  /metrics   Prometheus metrics\n"
    b"  /healthz   health (200 ok, 503 unhealthy), JSON\n"
    b"  /report/   the HTML trend report\n"
)


class Registered(Protocol):
    """What the endpoint serves of the metrics (:class:`monitor.service.outputs.metrics.ServiceMetrics`, a
    neighbour)."""

    registry: CollectorRegistry


class HealthView(Protocol):
    """What the endpoint serves of the health (:class:`monitor.service.health.Health`, a neighbour)."""

    def problems(self) -> list[str]: ...
    def running(self) -> list[dict]: ...


class _Handler(SimpleHTTPRequestHandler):
    server_version = "crisgeo"
    sys_version = ""

    def __init__(self, *args: Any, endpoint: Endpoint, **kwargs: Any) -> None:
        self.endpoint = endpoint
        super().__init__(*args, **kwargs)

    def do_GET(self) -> None:
        self._route(head=False)

    def do_HEAD(self) -> None:
        self._route(head=True)

    def _not_allowed(self) -> None:
        self.send_response(405)
        self.send_header("Allow", "GET, HEAD")
        self.send_header("Content-Length", "0")
        self.end_headers()

    do_POST = do_PUT = do_DELETE = do_PATCH = do_OPTIONS = _not_allowed  # noqa: N815

    def _route(self, head: bool) -> None:
        path = self.path.split("?", 1)[0]
        if path == "/":
            self._send(200, INDEX, "text/plain; charset=utf-8", head)
        elif path == "/metrics":
            encode, content_type = choose_encoder(self.headers.get("Accept", ""))
            self._send(200, encode(self.endpoint.metrics.registry), content_type, head)
        elif path == "/healthz":
            problems = self.endpoint.health.problems()
            body = {
                "status": "unhealthy" if problems else "ok",
                "problems": problems,
                "running": self.endpoint.health.running(),
            }
            self._send(503 if problems else 200, json.dumps(body).encode(), "application/json", head)
        elif path == "/report":
            self.send_response(301)
            self.send_header("Location", "/report/")
            self.send_header("Content-Length", "0")
            self.end_headers()
        elif path.startswith("/report/") and self.directory is not None and "/." not in path:
            self.path = self.path[len("/report") :]
            super().do_HEAD() if head else super().do_GET()
        else:
            self._send(404, b"not found\n", "text/plain", head)

    def list_directory(self, path: str | os.PathLike[str]) -> None:
        self.send_error(404, "no listing")
        return None

    def _send(self, code: int, body: bytes, ctype: str, head: bool) -> None:
        self.send_response(code)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        if not head:
            self.wfile.write(body)

    def log_message(self, fmt: str, *args: Any) -> None:
        LOG.debug("%s %s", self.address_string(), fmt % args)


class _V6Server(ThreadingHTTPServer):
    address_family = socket.AF_INET6


class Endpoint:
    """Serves *metrics* (:class:`monitor.service.outputs.metrics.ServiceMetrics`), *health*
    (:class:`monitor.service.health.Health`) and the files under *report_dir* on (host, port); port 0 takes a
    free one (see :attr:`address`).

    Parameters
    ----------
    host : str
        The address to serve on.
    port : int
        The port; 0 takes a free one.
    metrics : Registered
        What ``/metrics`` serves.
    health : HealthView
        What ``/healthz`` serves.
    report_dir : Path or None
        The report's files, under ``/report/``.
    """

    def __init__(
        self, host: str, port: int, metrics: Registered, health: HealthView, report_dir: Path | None
    ) -> None:
        self.metrics = metrics
        self.health = health
        directory = str(report_dir) if report_dir else None
        handler = partial(_Handler, endpoint=self, directory=directory)
        server_cls = _V6Server if ":" in host else ThreadingHTTPServer
        try:
            self.server = server_cls((host, port), handler)
        except OSError as exc:
            raise OSError(f"http.listen {host}:{port}: cannot listen ({exc.strerror or exc})") from None
        self.server.daemon_threads = True
        self.thread = threading.Thread(target=self.server.serve_forever, name="http", daemon=True)

    @property
    def address(self) -> str:  # numpydoc ignore=RT01
        """HOST:PORT actually listened on (port 0 resolved)."""
        host, port = self.server.server_address[:2]
        host = host.decode() if isinstance(host, bytes) else str(host)
        return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"

    def start(self) -> "Endpoint":
        """Serve on a daemon thread.

        Returns
        -------
        Endpoint
            It, serving on a thread.
        """
        self.thread.start()
        LOG.info("serving /metrics, /healthz and /report/ on http://%s/", self.address)
        return self

    def stop(self) -> None:
        """Stop serving and close the socket."""
        self.server.shutdown()
        self.server.server_close()
        self.thread.join(timeout=5)
