"""The daemon's HTTP endpoint, served by a real daemon process on a loopback port: /metrics (parsed with
prometheus-client's parser), /healthz (healthy, then a run over its budget), /report/ (in Chromium too)."""

import io
import os
import signal
import socket
import subprocess
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
import requests
from prometheus_client.parser import text_string_to_metric_families

from benchmarks.servers import chromium_driver, free_port, wait_for
from monitor.service.store.sqlite import Store
from tests.invoke import CRISGEO, ROOT, run_crisgeo

DAY = "2024-06-01"


def _notify_socket(tmp_path):
    path = str(tmp_path / "notify.sock")
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(path)
    sock.settimeout(60)
    return sock, path


def _get(url, **kw):
    try:
        return requests.get(url, timeout=10, **kw)
    except requests.RequestException:
        return None


def _daemon(cfg, port, notify_path, tmp_path):
    env = dict(os.environ, NOTIFY_SOCKET=notify_path, WATCHDOG_USEC="400000")
    log = open(tmp_path / "daemon.log", "w")
    return subprocess.Popen(
        CRISGEO + ["daemon", "--config", str(cfg), "--listen", f"127.0.0.1:{port}"],
        env=env,
        cwd=ROOT,
        stdout=log,
        stderr=log,
    )


def _stop(proc):
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()


@pytest.fixture(scope="module")
def served(cases, tmp_path_factory):
    """A store with one assessed day (``crisgeo run``), then the daemon on it, its catch-up done."""
    data, _, _ = cases.get()
    tmp = tmp_path_factory.mktemp("served")
    cfg = tmp / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp / 'state'}\nsource: {{kind: local, path: {data}}}\n"
        f"assessment: {{workers: 1}}\nschedule: {{catch_up_days: 1}}\nreport_dir: {tmp / 'report'}\n"
        f"report_url: https://crisgeo.example.org/report/\n"
    )
    r = run_crisgeo("run", "--config", cfg, "--date", DAY)
    assert r.returncode == 0, r.stderr
    (tmp / "report" / "empty").mkdir()
    sock, notify = _notify_socket(tmp)
    port = free_port()
    proc = _daemon(cfg, port, notify, tmp)
    db = tmp / "state" / "crisgeo.sqlite"
    try:
        assert sock.recv(4096) == b"READY=1"
        runs = lambda: [r.status for r in Store(db).runs()]  # noqa: E731
        assert wait_for(lambda: "no_data" in runs(), 120), (tmp / "daemon.log").read_text()
        yield f"http://127.0.0.1:{port}", db
    finally:
        _stop(proc)
        sock.close()


def _families(url):
    r = requests.get(url + "/metrics", timeout=10)
    assert r.status_code == 200 and r.headers["Content-Type"].startswith("text/plain")
    return {f.name: f for f in text_string_to_metric_families(r.text)}


def _samples(fam, name=None, **labels):
    return [
        s
        for s in fam.samples
        if (name is None or s.name == name) and all(s.labels.get(k) == v for k, v in labels.items())
    ]


@pytest.mark.servers
def test_metrics_after_a_run(served):
    url, db = served
    # the daemon's catch-up run is recorded in the ledger before its figures reach the gauges
    assert wait_for(lambda: _samples(_families(url)["crisgeo_run_duration_seconds"], satellite="j01"), 30)
    fams = _families(url)
    (last,) = _samples(fams["crisgeo_last_success_timestamp_seconds"], satellite="j01")
    assert abs(last.value - time.time()) < 3600
    runs = {
        s.labels["outcome"]: s.value
        for s in _samples(fams["crisgeo_runs"], "crisgeo_runs_total", satellite="j01")
    }
    assert runs["ok"] == 1 and runs["no_data"] >= 1 and runs["failed"] == 0
    assert "running" not in runs  # a counter only grows: runs under way are a gauge of their own
    assert {s.value for s in _samples(fams["crisgeo_runs_in_progress"], satellite="j01")} <= {0.0, 1.0}
    (since,) = _samples(fams["crisgeo_watched_since_timestamp_seconds"], satellite="j01")
    assert since.value <= last.value
    stages = {s.labels["stage"] for s in _samples(fams["crisgeo_run_duration_seconds"], satellite="j01")}
    assert "list" in stages
    assert (
        _samples(fams["crisgeo_downloaded_granules"], "crisgeo_downloaded_granules_total", satellite="j01")[
            0
        ].value
        == 0
    )
    assert _samples(fams["crisgeo_downloaded_bytes"], "crisgeo_downloaded_bytes_total", satellite="j01")
    assert _samples(fams["crisgeo_nodd_requests"], "crisgeo_nodd_requests_total", satellite="j01")
    assert fams["crisgeo_outbox_points"].type == "gauge"
    assert fams["crisgeo_alerts_firing"].type == "gauge"
    assert all(
        {"satellite", "rule", "severity"} == set(s.labels) for s in fams["crisgeo_alerts_firing"].samples
    )
    store = Store(db)
    fors = store.day_result("j01", store.latest_day("j01"))
    store.close()
    # Prometheus' base units in the names, the FOR label zero-padded as the InfluxDB tag (it sorts)
    alpha = {
        s.labels["for"]: s.value
        for s in _samples(fams["crisgeo_for_offset_radians"], satellite="j01", direction="alpha")
    }
    assert sorted(alpha) == [f"{k:02d}" for k in range(1, 31)]
    assert all(abs(alpha[f"{f.for_index:02d}"] - f.d_alpha_urad * 1e-6) < 1e-12 for f in fors)
    total = {
        int(s.labels["for"]): s.value
        for s in _samples(fams["crisgeo_for_offset_meters"], satellite="j01", direction="total")
    }
    assert all(abs(total[f.for_index] - 1000 * f.total_km) < 1e-6 for f in fors)
    beyond = {
        int(s.labels["for"]): s.value for s in _samples(fams["crisgeo_for_beyond_spec"], satellite="j01")
    }
    assert beyond == {f.for_index: (1.0 if f.spec_breaches(1.5) else 0.0) for f in fors}
    assert sum(beyond.values()) > 0  # the paper's pattern: FORs 26-30 beyond
    for family, name, scale in (
        ("crisgeo_for_calibration_bias_kelvin", "bias_k", 1.0),
        ("crisgeo_for_calibration_gain_ratio", "gain_pct", 0.01),
    ):
        got = {int(s.labels["for"]): s.value for s in _samples(fams[family], satellite="j01")}
        assert got and all(
            abs(got[f.for_index] - scale * getattr(f, name)) < 1e-9 for f in fors if f.for_index in got
        )
        assert len(got) == sum(np.isfinite(getattr(f, name)) for f in fors)
    # CrIS minus VIIRS per band (the daily run compares I5 by default), a band label
    got = {
        int(s.labels["for"]): s.value
        for s in _samples(fams["crisgeo_for_cris_minus_viirs_kelvin"], satellite="j01", band="I5")
    }
    assert got and all(
        abs(got[f.for_index] - f.cris_minus_viirs_k_I5) < 1e-9 for f in fors if f.for_index in got
    )
    # the CrIS response's widths, in radians (Prometheus' base unit), where the day fitted one
    for level, name in (("0.5", "response_width_50_urad"), ("0.1", "response_width_10_urad")):
        got = {
            int(s.labels["for"]): s.value
            for s in _samples(fams["crisgeo_for_response_full_width_radians"], satellite="j01", level=level)
        }
        assert got and all(
            abs(got[f.for_index] - getattr(f, name) * 1e-6) < 1e-12 for f in fors if f.for_index in got
        )
        assert len(got) == sum(np.isfinite(getattr(f, name)) for f in fors)
    reliable = {
        int(s.labels["for"]): s.value for s in _samples(fams["crisgeo_for_reliable"], satellite="j01")
    }
    assert all(reliable[f.for_index] == (1 if f.reliable else 0) for f in fors)
    assert fams["crisgeo_healthy"].samples[0].value == 1
    assert _samples(fams["crisgeo_build_info"])[0].labels["version"]
    text = requests.get(url + "/metrics", timeout=10).text
    assert "_created" not in text and "_km" not in text and "_urad" not in text and "percent" not in text
    assert "process_start_time_seconds" in fams and "python_info" in fams
    # content negotiation, as prometheus-client's own handler does it
    om = requests.get(url + "/metrics", headers={"Accept": "application/openmetrics-text"}, timeout=10)
    assert om.headers["Content-Type"].startswith("application/openmetrics-text")
    assert om.text.rstrip().endswith("# EOF")


@pytest.mark.servers
def test_healthz_when_all_is_well(served):
    url, _ = served
    r = requests.get(url + "/healthz", timeout=10)
    assert r.status_code == 200 and r.json()["status"] == "ok" and r.json()["problems"] == []


@pytest.mark.servers
def test_report_served_read_only(served, tmp_path):
    url, _ = served
    index = requests.get(url + "/report/", timeout=10)
    assert index.status_code == 200 and "j01" in index.text
    assert requests.get(url + "/report", timeout=10, allow_redirects=False).headers["Location"] == "/report/"
    page = requests.get(url + "/report/j01/", timeout=10)
    assert page.status_code == 200 and "trend.png" in page.text
    png = requests.get(url + "/report/j01/trend.png", timeout=10)
    assert png.headers["Content-Type"] == "image/png"
    image = plt.imread(io.BytesIO(png.content), format="png")
    assert image.ndim == 3 and image.shape[0] > 100 and image.shape[1] > 100
    (Path(served[1]).parents[1] / "report" / ".trend.png.part").write_bytes(b"half")
    for bad in (
        "/report/../c.yaml",
        "/report/%2e%2e/c.yaml",
        "/report/empty/",
        "/report/.trend.png.part",
        "/c.yaml",
    ):
        assert requests.get(url + bad, timeout=10).status_code == 404, bad
    index = requests.get(url + "/", timeout=10)
    assert index.status_code == 200 and all(p in index.text for p in ("/metrics", "/healthz", "/report/"))
    for method in ("POST", "PUT", "DELETE", "PATCH"):
        answer = requests.request(method, url + "/metrics", timeout=10)
        assert (answer.status_code, answer.headers["Allow"]) == (405, "GET, HEAD"), method
    driver = chromium_driver(tmp_path)
    try:
        driver.get(url + "/report/j01/")
        images = driver.execute_script(
            "return Array.from(document.images).map(i => [i.src, i.complete, i.naturalWidth]);"
        )
        assert images and all(ok and width > 0 for _, ok, width in images), images
        assert not [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
    finally:
        driver.quit()


@pytest.mark.servers
def test_a_run_over_its_budget_makes_the_daemon_unhealthy_and_starves_the_watchdog(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: simulated, granules: 1}}\n"
        f"assessment: {{workers: 1}}\nschedule: {{catch_up_days: 3, run_budget_min: 0.01}}\n"
    )
    sock, notify = _notify_socket(tmp_path)
    port = free_port()
    proc = _daemon(cfg, port, notify, tmp_path)
    url = f"http://127.0.0.1:{port}"
    try:
        got = []
        while "READY=1" not in got:
            got.append(sock.recv(4096).decode())
        assert wait_for(lambda: (r := _get(url + "/healthz")) is not None and r.status_code == 503, 60)
        body = requests.get(url + "/healthz", timeout=10).json()
        assert body["status"] == "unhealthy" and "over its budget of 1 s" in body["problems"][0]
        assert body["running"][0]["job"].startswith("run j01 ")
        deadline = time.time() + 5
        while not any(m.startswith("STATUS=unhealthy: run j01") for m in got) and time.time() < deadline:
            got.append(sock.recv(4096).decode())
        assert any(m.startswith("STATUS=unhealthy: run j01") for m in got), got
        # from here on, while unhealthy, no watchdog keep-alive (it would come every 0.2 s)
        later, until = [], time.time() + 1.5
        sock.settimeout(0.1)
        while time.time() < until:
            try:
                later.append(sock.recv(4096).decode())
            except socket.timeout:
                pass
        assert requests.get(url + "/healthz", timeout=10).status_code == 503
        assert "WATCHDOG=1" not in later, later
        fams = _families(url)
        assert fams["crisgeo_healthy"].samples[0].value == 0
    finally:
        _stop(proc)
        sock.close()
    assert proc.returncode == 128 + signal.SIGTERM  # stopped cleanly by SIGTERM


@pytest.mark.servers
def test_listen_is_checked(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: simulated}}\n")
    r = run_crisgeo("daemon", "--config", cfg, "--listen", "nonsense", timeout=60)
    assert r.returncode == 2 and "--listen: 'nonsense' is not HOST:PORT" in r.stderr
    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen()
    port = taken.getsockname()[1]
    try:
        r = run_crisgeo("daemon", "--config", cfg, "--listen", f"127.0.0.1:{port}", timeout=60)
    finally:
        taken.close()
    assert r.returncode == 1 and f"http.listen 127.0.0.1:{port}: cannot listen" in r.stderr, r.stderr


def test_a_satellite_that_never_succeeded_is_visible_to_the_dead_mans_rule(tmp_path):
    """Its last success is 0 and it is watched since its first run (or the process start): the rule's
    `(last > 0) or watched_since` then counts the time without success."""
    import datetime as dt

    from prometheus_client import generate_latest

    from monitor.service.health import Health
    from monitor.service.outputs.metrics import ServiceMetrics

    db = tmp_path / "s.sqlite"
    with Store(db) as store:
        run = store.begin_run("j01", dt.date(2024, 6, 1))
        store.finish_run(run, "failed", "HTTP 503")
    m = ServiceMetrics(lambda: Store(db), ["j01", "npp"], Health(60), "test", 1.5)
    fams = {f.name: f for f in text_string_to_metric_families(generate_latest(m.registry).decode())}
    last = {s.labels["satellite"]: s.value for s in fams["crisgeo_last_success_timestamp_seconds"].samples}
    since = {s.labels["satellite"]: s.value for s in fams["crisgeo_watched_since_timestamp_seconds"].samples}
    assert last == {"j01": 0.0, "npp": 0.0}
    assert abs(since["j01"] - time.time()) < 600 and abs(since["npp"] - time.time()) < 600
    runs = {(s.labels["satellite"], s.labels["outcome"]): s.value for s in fams["crisgeo_runs"].samples}
    assert runs[("j01", "failed")] == 1 and ("j01", "running") not in runs
