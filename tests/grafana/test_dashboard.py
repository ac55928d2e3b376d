"""Every query of the Grafana dashboard, run against a real InfluxDB 1.x with fixture results."""

import datetime as dt
import json
import re
import time
from pathlib import Path

import pytest
import requests

from benchmarks.servers import influxdb1, influxql
from monitor.history.changes import Change
from monitor.service.outputs.timeseries import change_lines, result_lines
from monitor.service.store.sqlite import Store
from monitor.simulate.history import BAND_LEVEL_K, fill_store

pytestmark = pytest.mark.servers  # starts real servers, daemons or tools (see pyproject markers)

DASHBOARD = Path(__file__).resolve().parents[2] / "configs" / "grafana" / "crisgeo-dashboard.json"
FIRST, DAYS = dt.date(2025, 1, 1), 60
RELIABLE = {}  # satellite -> {FOR: days with a reliable result}, filled by the influx fixture
UTC = dt.timezone.utc


def _macros(q: str, satellite="j01", fors=("01", "15", "30")) -> str:
    """The query as Grafana sends it: time range, interval and (multi-value regex) variables substituted."""
    t0 = int(dt.datetime(2024, 12, 1, tzinfo=UTC).timestamp() * 1000)
    t1 = int(dt.datetime(2025, 6, 1, tzinfo=UTC).timestamp() * 1000)
    q = q.replace("$timeFilter", f"time >= {t0}ms and time <= {t1}ms").replace("$__interval", "1d")
    q = q.replace("/^$satellite$/", f"/^{satellite}$/").replace("/^$for$/", f"/^({'|'.join(fors)})$/")
    assert "$" not in q.replace("$/", ""), q
    return q


@pytest.fixture(scope="module")
def influx(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("influx1")
    store = Store(tmp / "s.sqlite")
    days = fill_store(store, ["npp", "j01"], FIRST, DAYS, step_day=40)
    lines = []
    RELIABLE.clear()
    for sat in ("npp", "j01"):
        RELIABLE[sat] = {k: 0 for k in range(1, 31)}
        for day in days:
            fors = store.day_result(sat, day)
            lines += result_lines("cris_geolocation", sat, day, fors)
            for f in fors:
                RELIABLE[sat][f.for_index] += f.reliable
    change = Change(
        dt.datetime(2025, 2, 10, 6, tzinfo=UTC), "j01", "cris", "ep_upload", "EP V116 uploaded", "calendar"
    )
    lines += change_lines("cris_geolocation", [change])
    store.close()
    with influxdb1(tmp / "srv") as url:
        requests.post(url + "/query", data={"q": 'CREATE DATABASE "crisgeo"'}, timeout=10).raise_for_status()
        r = requests.post(
            url + "/write", params={"db": "crisgeo", "precision": "s"}, data="\n".join(lines), timeout=30
        )
        assert r.status_code == 204, r.text
        yield url


@pytest.fixture(scope="module")
def dashboard():
    return json.loads(DASHBOARD.read_text())


def _values(series):
    return sorted(v[1] for s in series for v in s["values"])


def test_variables(influx, dashboard):
    variables = {v["name"]: v for v in dashboard["templating"]["list"]}
    assert variables["datasource"]["query"] == "influxdb"
    assert _values(influxql(influx, "crisgeo", variables["satellite"]["query"])) == ["j01", "npp"]
    assert _values(influxql(influx, "crisgeo", _macros(variables["for"]["query"]))) == [
        f"{k:02d}" for k in range(1, 31)
    ]


def _influx_panels(dashboard):
    return [p for p in dashboard["panels"] if p.get("datasource", {}).get("type") == "influxdb"]


def test_every_panel_query(influx, dashboard):
    reliable = RELIABLE
    seen = set()
    for panel in _influx_panels(dashboard):
        for t in panel["targets"]:
            assert t["rawQuery"] and t["datasource"]["uid"] == "${datasource}"
            series = influxql(influx, "crisgeo", _macros(t["query"]))
            tags = sorted(s["tags"].get("for", "") for s in series)
            if panel["type"] == "heatmap":
                assert tags == [f"{k:02d}" for k in range(1, 31)]
                # flagged results are left out: each FOR has a value on each of its reliable days only
                assert all(len(s["values"]) == reliable["j01"][int(s["tags"]["for"])] for s in series)
                cross = {v[0]: v[1] for v in [s for s in series if s["tags"]["for"] == "30"][0]["values"]}
                if "cross_track_km" in t["query"]:  # the injected step at day 40 shows in FOR 30
                    times = sorted(cross)
                    assert cross[times[-15]] - cross[times[5]] > 0.5
            elif panel["type"] == "timeseries" and "cris_geolocation_band" in t["query"]:
                # CrIS minus VIIRS per band: a line per band, each day's median near the history's level
                bands = sorted(s["tags"]["band"] for s in series)
                assert bands == ["I5", "M13", "M15", "M16"], bands
                for s in series:
                    level = BAND_LEVEL_K[s["tags"]["band"]]
                    assert all(abs(v[1] - level) < 0.05 for v in s["values"]), s["tags"]
            elif panel["type"] == "timeseries":
                assert tags == ["01", "15", "30"]
                assert all(len(s["values"]) == reliable["j01"][int(s["tags"]["for"])] for s in series)
                assert panel["fieldConfig"]["defaults"]["thresholds"]["steps"][2]["value"] == 1.5
            elif panel["type"] == "barchart":
                assert tags == [f"{k:02d}" for k in range(1, 31)]
                assert all(s["columns"] == ["time", "in_track_km", "cross_track_km"] for s in series)
                assert all(len(s["values"]) == 1 for s in series)  # the last value per FOR
            elif panel["type"] == "table":  # the flagged results, and only those
                flagged = {k: DAYS - n for k, n in reliable["j01"].items() if n < DAYS}
                assert flagged and {int(s["tags"]["for"]): len(s["values"]) for s in series} == flagged
            seen.add(panel["type"])
    assert seen == {"heatmap", "timeseries", "barchart", "table"}


def test_annotations_from_changes(influx, dashboard):
    (ann,) = dashboard["annotations"]["list"]
    rows = influxql(influx, "crisgeo", _macros(ann["query"]))
    assert [v[1] for v in rows[0]["values"]] == ["EP V116 uploaded"]
    assert rows[0]["values"][0][0] == int(dt.datetime(2025, 2, 10, 6, tzinfo=UTC).timestamp())
    assert influxql(influx, "crisgeo", _macros(ann["query"], satellite="npp")) == []


def test_every_query_names_the_measurement_and_the_satellite(dashboard):
    queries = [t["query"] for p in _influx_panels(dashboard) for t in p["targets"]] + [
        a["query"] for a in dashboard["annotations"]["list"]
    ]
    for q in queries:
        assert (
            re.search(r'FROM "cris_geolocation(_change|_band)?"', q)
            and "/^$satellite$/" in q
            and "$timeFilter" in q
        )


def test_service_health_row_queries_the_daemon_metrics(dashboard, tmp_path):
    """Every PromQL panel of the health row, run by VictoriaMetrics (PromQL) on two scrapes of the daemon's
    metrics (a store with runs, a failed run, outbox points and a firing alert)."""
    from prometheus_client import generate_latest

    from alerts.rules import Finding
    from benchmarks.servers import victoria_metrics, wait_for
    from monitor.service.health import Health
    from monitor.service.outputs.metrics import ServiceMetrics
    from monitor.service.store.alert_state import AlertState

    db = tmp_path / "s.sqlite"
    ten_hours_ago = dt.datetime.now(UTC) - dt.timedelta(hours=10)
    with Store(db, clock=lambda: ten_hours_ago) as earlier:  # the last success, 10 h ago
        fill_store(earlier, ["j01"], dt.date.today() - dt.timedelta(days=3), 3)
    store = Store(db)
    store.finish_run(store.begin_run("j01", dt.date.today()), "failed", "HTTP 503")
    store.queue_lines("influx2:db.example", "j01", ["m x=1 1"] * 3)
    AlertState(store).upsert(
        Finding("spec", "j01", "critical", "FOR 30 beyond spec"), dt.datetime.now(UTC), True
    )
    store.close()
    metrics = ServiceMetrics(lambda: Store(db), ["j01"], Health(300), "test", 1.5)
    panels = [p for p in dashboard["panels"] if p.get("datasource", {}).get("type") == "prometheus"]
    assert {p["type"] for p in panels} == {"stat", "timeseries"} and len(panels) == 5
    assert any(
        v["name"] == "prometheus" and v["query"] == "prometheus" for v in dashboard["templating"]["list"]
    )
    now = int(time.time())
    with victoria_metrics(tmp_path / "vm") as url:
        text = generate_latest(metrics.registry).decode()
        for t in (now - 3600, now - 60):
            r = requests.post(
                url + "/api/v1/import/prometheus", params={"timestamp": t * 1000}, data=text, timeout=10
            )
            assert r.status_code == 204, r.text
        requests.get(url + "/internal/force_flush", timeout=10)

        def answer(panel):
            q = panel["targets"][0]["expr"].replace('=~"$satellite"', '=~"j01"')
            return requests.get(url + "/api/v1/query", params={"query": q, "time": now}, timeout=10).json()

        assert wait_for(lambda: answer(panels[0])["data"]["result"], 30)  # the samples are searchable
        for panel in panels:
            (target,) = panel["targets"]
            assert target["datasource"]["uid"] == "${prometheus}"
            r = answer(panel)
            assert r["status"] == "success" and r["data"]["result"], (panel["title"], r)
            values = {tuple(sorted(x["metric"].items())): float(x["value"][1]) for x in r["data"]["result"]}
            if panel["title"].startswith("Hours since"):
                (hours,) = values.values()
                assert abs(hours - 10) < 0.1
            elif panel["title"] == "Outbox points waiting":
                assert list(values.values()) == [3.0]
            elif panel["title"] == "Alerts firing":
                assert values == {(("severity", "critical"),): 1.0}
            elif panel["title"] == "Healthy":
                assert list(values.values()) == [1.0]
