"""Real servers for the tests, on loopback: VictoriaMetrics, InfluxDB 1.x, and an S3-style HTTP server.

The database servers come from Debian packages (``victoria-metrics``, ``influxdb``), which ``.ci/run``
installs. Without them a test is skipped locally but fails under CI (``CI=true``).
"""

from __future__ import annotations

import base64
import os
import shutil
import socket
import subprocess
import threading
import time
import urllib.parse
from contextlib import contextmanager
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from xml.sax.saxutils import escape

import pytest
import requests


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def require(binary: str) -> str:
    path = shutil.which(binary)
    if path is None:
        msg = f"{binary} is not installed (Debian package); .ci/run installs it"
        if os.environ.get("CI"):
            pytest.fail(msg)
        pytest.skip(msg)
    return path


def _wait(url: str, ok=(200, 204), timeout=30.0):
    t0 = time.time()
    while time.time() - t0 < timeout:
        try:
            if requests.get(url, timeout=1).status_code in ok:
                return
        except requests.RequestException:
            pass
        time.sleep(0.2)
    raise RuntimeError(f"server at {url} did not come up in {timeout} s")


@contextmanager
def _running(cmd: list, url: str, health: str):
    """Run server *cmd*, wait until *url* + *health* answers, yield *url*; stop the server after."""
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        _wait(url + health)
        yield url
    finally:
        proc.terminate()
        proc.wait(timeout=30)


@contextmanager
def victoria_metrics(tmp: Path, port: int | None = None):
    """VictoriaMetrics on 127.0.0.1; yields its base URL."""
    exe = require("victoria-metrics")
    port = port or free_port()
    with _running([exe, f"-httpListenAddr=127.0.0.1:{port}", f"-storageDataPath={tmp}", "-retentionPeriod=100y",
                   "-loggerLevel=ERROR"], f"http://127.0.0.1:{port}", "/health") as url:
        yield url


def vm_export(url: str, metric_regex: str) -> list[dict]:
    """Every stored series matching *metric_regex*, after forcing VictoriaMetrics to flush."""
    import json
    requests.get(url + "/internal/force_flush", timeout=10)
    r = requests.get(url + "/api/v1/export", params={"match[]": f'{{__name__=~"{metric_regex}"}}'}, timeout=30)
    r.raise_for_status()
    return [json.loads(line) for line in r.text.splitlines() if line.strip()]


@contextmanager
def influxdb1(tmp: Path):
    """InfluxDB 1.x on 127.0.0.1 with its own config and data directories; yields its base URL."""
    exe = require("influxd")
    http, rpc = free_port(), free_port()
    tmp.mkdir(parents=True, exist_ok=True)
    conf = tmp / "influxdb.conf"
    conf.write_text(f"""reporting-disabled = true
bind-address = "127.0.0.1:{rpc}"
[meta]
  dir = "{tmp}/meta"
[data]
  dir = "{tmp}/data"
  wal-dir = "{tmp}/wal"
  query-log-enabled = false
[http]
  bind-address = "127.0.0.1:{http}"
  log-enabled = false
[monitor]
  store-enabled = false
""")
    with _running([exe, "-config", str(conf)], f"http://127.0.0.1:{http}", "/ping") as url:
        yield url


def influxql(url: str, db: str, q: str) -> list:
    r = requests.get(url + "/query", params={"db": db, "q": q, "epoch": "s"}, timeout=30)
    r.raise_for_status()
    res = r.json()["results"][0]
    if "error" in res:
        raise RuntimeError(res["error"])
    return res.get("series", [])


class S3Server:
    """A minimal S3-style server (path style: /<bucket>/<key>) over a directory of buckets.

    ListObjectsV2 with ``page_size`` keys per page and continuation tokens; GET of objects. Faults:
    ``drop_once`` names keys whose first download is cut half-way; ``extra_keys`` adds listed keys
    that do not exist (e.g. a path-traversal attempt).
    """

    def __init__(self, root: Path, page_size: int = 3):
        self.root = Path(root)
        self.page_size = page_size
        self.drop_once = set()
        self.extra_keys = []
        self.requests = []
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *a):
                pass

            def do_GET(self):
                server.requests.append(self.path)
                parsed = urllib.parse.urlparse(self.path)
                parts = parsed.path.lstrip("/").split("/", 1)
                bucket = parts[0]
                key = urllib.parse.unquote(parts[1]) if len(parts) > 1 else ""
                if not key:
                    return server._list(self, bucket, urllib.parse.parse_qs(parsed.query))
                return server._get(self, bucket, key)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.httpd.shutdown()
        self.httpd.server_close()

    def _list(self, h, bucket, q):
        prefix = q.get("prefix", [""])[0]
        base = self.root / bucket
        keys = sorted(str(p.relative_to(base)) for p in base.rglob("*") if p.is_file())
        keys = sorted(set(k for k in keys + self.extra_keys if k.startswith(prefix)))
        start = int(base64.b64decode(q["continuation-token"][0]).decode()) if "continuation-token" in q else 0
        page = keys[start:start + self.page_size]
        more = start + self.page_size < len(keys)
        items = "".join(
            f"<Contents><Key>{escape(k)}</Key><Size>{(base / k).stat().st_size if (base / k).is_file() else 10}"
            f"</Size></Contents>" for k in page)
        token = (f"<NextContinuationToken>{base64.b64encode(str(start + self.page_size).encode()).decode()}"
                 f"</NextContinuationToken>" if more else "")
        body = (f'<?xml version="1.0" encoding="UTF-8"?><ListBucketResult xmlns="http://s3.amazonaws.com/doc/2006-03-01/">'
                f"<Name>{bucket}</Name><Prefix>{escape(prefix)}</Prefix><KeyCount>{len(page)}</KeyCount>"
                f"<IsTruncated>{'true' if more else 'false'}</IsTruncated>{token}{items}</ListBucketResult>").encode()
        h.send_response(200)
        h.send_header("Content-Type", "application/xml")
        h.send_header("Content-Length", str(len(body)))
        h.end_headers()
        h.wfile.write(body)

    def _get(self, h, bucket, key):
        path = (self.root / bucket / key).resolve()
        if not path.is_file() or self.root.resolve() not in path.parents:
            h.send_response(404)
            h.send_header("Content-Length", "0")
            h.end_headers()
            return
        data = path.read_bytes()
        h.send_response(200)
        h.send_header("Content-Length", str(len(data)))
        h.end_headers()
        if key in self.drop_once:
            self.drop_once.discard(key)
            h.wfile.write(data[: len(data) // 2])
            h.wfile.flush()
            h.connection.shutdown(socket.SHUT_RDWR)
            return
        h.wfile.write(data)
