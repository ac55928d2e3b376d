"""Real servers on loopback, for the tests and the harnesses: VictoriaMetrics, InfluxDB 1.x, S3-style HTTP.

The database servers come from Debian packages (``victoria-metrics``, ``influxdb``), which ``.ci/run``
installs. Without them a test is skipped locally but fails under CI (``CI=true``).
"""

from __future__ import annotations

import base64
import json
import os
import re
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


def wait_for(pred, timeout=120.0) -> bool:
    """Poll *pred* every 0.2 s until it is true (True) or *timeout* seconds have passed (False)."""
    t0 = time.time()
    while time.time() - t0 < timeout:
        if pred():
            return True
        time.sleep(0.2)
    return False


def chromium_driver(tmp_path):
    """Headless Chromium under Selenium, keeping the browser console log (read it with get_log)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = require("chromium")
    for arg in (
        "--headless=new",
        "--no-sandbox",
        "--disable-dev-shm-usage",
        "--window-size=1280,2400",
        f"--user-data-dir={tmp_path / 'chrome-profile'}",
    ):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(require("chromedriver")), options=options)


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
def victoria_metrics(tmp: Path, port: int | None = None, flags=()):
    """VictoriaMetrics on 127.0.0.1 (with extra command-line *flags*); yields its base URL."""
    exe = require("victoria-metrics")
    port = port or free_port()
    with _running(
        [
            exe,
            f"-httpListenAddr=127.0.0.1:{port}",
            f"-storageDataPath={tmp}",
            "-retentionPeriod=100y",
            "-loggerLevel=ERROR",
            *flags,
        ],
        f"http://127.0.0.1:{port}",
        "/health",
    ) as url:
        yield url


@contextmanager
def alertmanager(tmp: Path, webhook_url: str):
    """Alertmanager (Debian's prometheus-alertmanager) on 127.0.0.1, no cluster, routing every alert to
    *webhook_url* within about a second (resolved ones too); yields its base URL."""
    exe = require("prometheus-alertmanager")
    port = free_port()
    tmp.mkdir(parents=True, exist_ok=True)
    conf = tmp / "alertmanager.yml"
    conf.write_text(
        "route: {receiver: hook, group_by: [alertname, satellite], group_wait: 1s, group_interval: 1s, "
        "repeat_interval: 1h}\n"
        f"receivers: [{{name: hook, webhook_configs: [{{url: '{webhook_url}', send_resolved: true}}]}}]\n"
    )
    with _running(
        [
            exe,
            f"--config.file={conf}",
            f"--storage.path={tmp / 'data'}",
            f"--web.listen-address=127.0.0.1:{port}",
            "--cluster.listen-address=",
            "--log.level=error",
        ],
        f"http://127.0.0.1:{port}",
        "/-/ready",
    ) as url:
        yield url


def vm_export(url: str, metric_regex: str) -> list[dict]:
    """Every stored series matching *metric_regex*, after forcing VictoriaMetrics to flush."""
    import json

    requests.get(url + "/internal/force_flush", timeout=10)
    r = requests.get(
        url + "/api/v1/export", params={"match[]": f'{{__name__=~"{metric_regex}"}}'}, timeout=30
    )
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


class Webhook:
    """An HTTP endpoint that takes JSON posts (a Slack incoming webhook, an Alertmanager receiver): each
    body in ``received``; the answer from ``script`` (a list of (status, body, headers), popped in turn),
    else 500 while ``failing`` (those posts are counted in ``refused``, not received), else 200."""

    def __init__(self, path: str = "/services/T000/B000/secret-token"):
        self.script: list = []
        self.received: list = []
        self.failing, self.refused = False, 0
        hook = self

        class H(BaseHTTPRequestHandler):
            def log_message(self, *a):
                pass

            def do_POST(self):
                body = self.rfile.read(int(self.headers["Content-Length"]))
                if hook.script:
                    status, text, headers = hook.script.pop(0)
                    hook.received.append(json.loads(body))
                elif hook.failing:
                    (status, text, headers), hook.refused = (500, "down", {}), hook.refused + 1
                else:
                    (status, text, headers) = (200, "ok", {})
                    hook.received.append(json.loads(body))
                data = text.encode()
                self.send_response(status)
                for k, v in headers.items():
                    self.send_header(k, v)
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), H)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}{path}"
        threading.Thread(target=self.httpd.serve_forever, daemon=True).start()

    def close(self):
        """Stop serving."""
        self.httpd.shutdown()
        self.httpd.server_close()


def _drip(wfile, data: bytes, size: int, pause_s: float) -> None:
    """Write *data* *size* bytes at a time, *pause_s* apart."""
    for i in range(0, len(data), size):
        wfile.write(data[i : i + size])
        wfile.flush()
        time.sleep(pause_s)


class S3Server:
    """A minimal S3-style server (path style: /<bucket>/<key>) over a directory of buckets.

    ListObjectsV2 with ``page_size`` keys per page, continuation tokens and MD5 ETags; GET of objects.
    Faults, each off by default: ``drop_once`` (keys whose first download is cut half-way),
    ``corrupt_once`` (keys whose first answer holding byte ``corrupt_at`` has it changed),
    ``extra_keys`` (listed keys that do not exist, with ``extra_sizes`` giving their <Size> text),
    ``endless_tokens`` (every page is truncated,
    with a new token), ``repeat_token`` (every page is truncated, with the same token), ``slow_drip_s``
    (downloads trickle ``drip_bytes`` bytes per interval), ``slow_list_s`` (listing pages trickle one byte
    per interval), ``slow_headers_s`` (every answer's status line and headers trickle one byte per interval),
    ``retry_after`` (every request: 503 and this Retry-After),
    ``lying_size`` (the listing says this many bytes, and a range's Content-Range another size),
    ``gzip`` (downloads are gzip-encoded), ``redirect_to`` (the next download answers 302 to this base
    URL), ``short_ranges`` (a range answer holds half the bytes asked for, and says so) and
    ``ignore_ranges`` (a range request gets the whole object, 200). GET with a
    Range header answers 206 with that range, every fault applying to it.
    """

    def __init__(self, root: Path, page_size: int = 3, host: str = "127.0.0.1"):
        self.root = Path(root)
        self.page_size = page_size
        self.drop_once: set = set()
        self.corrupt_once: set = set()
        self.extra_keys: list = []
        self.extra_sizes: dict = {}
        self.endless_tokens = self.repeat_token = self.gzip = self.short_ranges = self.ignore_ranges = False
        self.slow_drip_s = self.retry_after = self.lying_size = self.redirect_to = None
        self.slow_list_s = self.slow_headers_s = None
        self.drip_bytes = 64
        self.corrupt_at = 100  # the byte corrupt_once flips
        self.requests: list = []
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *a):
                pass

            def do_GET(self):
                server.requests.append(self.path)
                if server.slow_headers_s is not None:
                    head = b"HTTP/1.1 200 OK\r\nContent-Type: application/xml\r\nContent-Length: 10\r\n\r\n"
                    try:
                        _drip(self.wfile, head, 1, server.slow_headers_s)
                    except (BrokenPipeError, ConnectionResetError, OSError):
                        pass  # the client gave up, as it should
                    return
                if server.retry_after is not None:
                    self.send_response(503)
                    self.send_header("Retry-After", str(server.retry_after))
                    self.send_header("Content-Length", "0")
                    self.end_headers()
                    return
                parsed = urllib.parse.urlparse(self.path)
                parts = parsed.path.lstrip("/").split("/", 1)
                bucket = parts[0]
                key = urllib.parse.unquote(parts[1]) if len(parts) > 1 else ""
                if not key:
                    return server._list(self, bucket, urllib.parse.parse_qs(parsed.query))
                return server._get(self, bucket, key)

        self.httpd = ThreadingHTTPServer((host, 0), Handler)
        self.httpd.daemon_threads = True
        self.url = f"http://{host}:{self.httpd.server_address[1]}"
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)

    def __enter__(self):
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.httpd.shutdown()
        self.httpd.server_close()

    def _list(self, h, bucket, q):
        import hashlib

        prefix = q.get("prefix", [""])[0]
        base = self.root / bucket
        keys = sorted(str(p.relative_to(base)) for p in base.rglob("*") if p.is_file())
        keys = sorted(set(k for k in keys + self.extra_keys if k.startswith(prefix)))
        token_in = q.get("continuation-token", [None])[0]
        start = (
            int(base64.b64decode(token_in).decode().split(":")[0])
            if token_in and not self.repeat_token
            else 0
        )
        page = keys[start : start + self.page_size]
        more = start + self.page_size < len(keys) or self.endless_tokens or self.repeat_token

        def size(k):
            if k in self.extra_sizes:
                return self.extra_sizes[k]
            if self.lying_size is not None:
                return str(self.lying_size)
            return str((base / k).stat().st_size) if k not in self.extra_keys else "10"

        def etag(k):
            return (
                f"<ETag>&quot;{hashlib.md5((base / k).read_bytes()).hexdigest()}&quot;</ETag>"
                if k not in self.extra_keys
                else ""
            )

        items = "".join(
            f"<Contents><Key>{escape(k)}</Key><Size>{escape(size(k))}</Size>{etag(k)}</Contents>"
            for k in page
        )
        nxt = start + self.page_size if start + self.page_size < len(keys) else 0
        token = base64.b64encode(f"{0 if self.repeat_token else nxt}:{len(self.requests)}".encode()).decode()
        if self.repeat_token:
            token = "c2FtZQ=="
        token = f"<NextContinuationToken>{token}</NextContinuationToken>" if more else ""
        body = (
            f'<?xml version="1.0" encoding="UTF-8"?><ListBucketResult xmlns="http://s3.amazonaws.com/doc/2006-03-01/">'
            f"<Name>{bucket}</Name><Prefix>{escape(prefix)}</Prefix><KeyCount>{len(page)}</KeyCount>"
            f"<IsTruncated>{'true' if more else 'false'}</IsTruncated>{token}{items}</ListBucketResult>"
        ).encode()
        h.send_response(200)
        h.send_header("Content-Type", "application/xml")
        h.send_header("Content-Length", str(len(body)))
        h.end_headers()
        try:
            if self.slow_list_s is not None:
                return _drip(h.wfile, body, 1, self.slow_list_s)
            h.wfile.write(body)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the client gave up, as it should

    def _get(self, h, bucket, key):
        if self.redirect_to is not None:
            target, self.redirect_to = self.redirect_to, None  # once
            h.send_response(302)
            h.send_header("Location", f"{target}/{bucket}/{key}")
            h.send_header("Content-Length", "0")
            h.end_headers()
            return
        path = (self.root / bucket / key).resolve()
        if not path.is_file() or self.root.resolve() not in path.parents:
            h.send_response(404)
            h.send_header("Content-Length", "0")
            h.end_headers()
            return
        data = path.read_bytes()
        size, wanted = len(data), re.fullmatch(r"bytes=(\d+)-(\d+)", h.headers.get("Range", ""))
        if self.ignore_ranges:
            wanted = None
        at = self.corrupt_at
        if key in self.corrupt_once and (not wanted or int(wanted[1]) <= at <= int(wanted[2])):
            self.corrupt_once.discard(key)  # the first answer holding the byte
            data = data[:at] + bytes([data[at] ^ 0xFF]) + data[at + 1 :]
        if wanted:  # a range: the faults apply to its bytes as to a whole object's
            first, last = int(wanted[1]), min(int(wanted[2]), size - 1)
            data = data[first : last + 1]
            if self.short_ranges:
                data = data[: len(data) // 2]
        if self.gzip:
            import gzip

            data = gzip.compress(data)
        h.send_response(206 if wanted else 200)
        if self.gzip:
            h.send_header("Content-Encoding", "gzip")
        if wanted:
            h.send_header(
                "Content-Range", f"bytes {first}-{last}/{size if self.lying_size is None else 10**9}"
            )
        h.send_header("Content-Length", str(len(data)))
        h.end_headers()
        try:
            if key in self.drop_once:
                self.drop_once.discard(key)
                h.wfile.write(data[: len(data) // 2])
                h.wfile.flush()
                h.connection.shutdown(socket.SHUT_RDWR)
                return
            if self.slow_drip_s is not None:
                return _drip(h.wfile, data, self.drip_bytes, self.slow_drip_s)
            h.wfile.write(data)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the client gave up, as it should


def nodd_key(name: str) -> str:
    """The NODD key of a granule file: ``<collection>/YYYY/MM/DD/<name>`` (docs/archive.md), the folder
    from the product table, the day from the name."""
    from monitor.sdr.names import parse_name
    from monitor.sdr.products import PRODUCTS

    parsed = parse_name(name)
    assert parsed is not None, name
    return f"{PRODUCTS[parsed.products[0]].collection}/{parsed.start:%Y/%m/%d}/{name}"


class MotoS3:
    """moto's S3 server (a real S3-compatible HTTP server, in a thread) on loopback, holding public
    buckets as NODD's are: anonymous ListObjectsV2 and GET, range requests, MD5 ETags (every object
    is put in one part)."""

    def __init__(self):
        from moto.server import ThreadedMotoServer

        self.server = ThreadedMotoServer(ip_address="127.0.0.1", port=0, verbose=False)
        self.url = ""
        self.client = None

    def __enter__(self):
        import logging

        import boto3

        logging.getLogger("werkzeug").setLevel(logging.WARNING)  # a line per request otherwise
        self.server.start()
        host, port = self.server.get_host_and_port()
        self.url = f"http://{host}:{port}"
        requests.post(f"{self.url}/moto-api/reset", timeout=30)  # moto's state is per process: start empty
        self.client = boto3.client(
            "s3",
            endpoint_url=self.url,
            region_name="us-east-1",
            aws_access_key_id="test",
            aws_secret_access_key="test",
        )
        return self

    def __exit__(self, *exc):
        self.server.stop()

    def put_granules(self, bucket: str, files) -> list[str]:
        """Put granule *files* under their NODD keys (``<collection>/YYYY/MM/DD/<name>``) in *bucket*
        (made public); the keys."""
        from boto3.s3.transfer import TransferConfig

        existing = {b["Name"] for b in self.client.list_buckets().get("Buckets", [])}
        if bucket not in existing:
            self.client.create_bucket(Bucket=bucket, ACL="public-read")
        keys = []
        one_part = TransferConfig(multipart_threshold=1 << 40)  # a plain MD5 ETag, as NODD's granules
        for f in map(Path, files):
            key = nodd_key(f.name)
            self.client.upload_file(str(f), bucket, key, Config=one_part, ExtraArgs={"ACL": "public-read"})
            keys.append(key)
        return keys
