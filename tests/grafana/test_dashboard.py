"""Every query of the Grafana dashboard, run against a real InfluxDB 1.x with fixture results."""

import datetime as dt
import json
import re
from pathlib import Path

import pytest
import requests

from alerts.changes import Change
from monitor.simulate.history import fill_store
from monitor.store.sqlite import Store
from monitor.store.timeseries import change_lines, result_lines
from tests.servers import influxdb1, influxql

DASHBOARD = Path(__file__).resolve().parents[2] / "configs" / "grafana" / "crisgeo-dashboard.json"
FIRST, DAYS = dt.date(2025, 1, 1), 60
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
    for sat in ("npp", "j01"):
        for day in days:
            lines += result_lines("cris_geolocation", sat, day, store.day_result(sat, day))
    change = Change(dt.datetime(2025, 2, 10, 6, tzinfo=UTC), "j01", "cris", "ep_upload", "EP V116 uploaded", "calendar")
    lines += change_lines("cris_geolocation", [change])
    store.close()
    with influxdb1(tmp / "srv") as url:
        requests.post(url + "/query", data={"q": 'CREATE DATABASE "crisgeo"'}, timeout=10).raise_for_status()
        r = requests.post(url + "/write", params={"db": "crisgeo", "precision": "s"}, data="\n".join(lines), timeout=30)
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
    assert _values(influxql(influx, "crisgeo", _macros(variables["for"]["query"]))) == [f"{k:02d}" for k in range(1, 31)]


def test_every_panel_query(influx, dashboard):
    seen = set()
    for panel in dashboard["panels"]:
        for t in panel["targets"]:
            assert t["rawQuery"] and t["datasource"]["uid"] == "${datasource}"
            series = influxql(influx, "crisgeo", _macros(t["query"]))
            tags = sorted(s["tags"]["for"] for s in series)
            if panel["type"] == "heatmap":
                assert tags == [f"{k:02d}" for k in range(1, 31)]
                assert all(len(s["values"]) == DAYS for s in series)
                cross = [s for s in series if s["tags"]["for"] == "30"][0]["values"]
                if "cross_track_km" in t["query"]:  # the injected step at day 40 shows in FOR 30
                    assert cross[45][1] - cross[35][1] > 0.5
            elif panel["type"] == "timeseries":
                assert tags == ["01", "15", "30"] and all(len(s["values"]) == DAYS for s in series)
                assert panel["fieldConfig"]["defaults"]["thresholds"]["steps"][2]["value"] == 1.5
            elif panel["type"] == "barchart":
                assert tags == [f"{k:02d}" for k in range(1, 31)]
                assert all(s["columns"] == ["time", "in_track_km", "cross_track_km"] for s in series)
                assert all(len(s["values"]) == 1 for s in series)  # the last value per FOR
            seen.add(panel["type"])
    assert seen == {"heatmap", "timeseries", "barchart"}


def test_annotations_from_changes(influx, dashboard):
    (ann,) = dashboard["annotations"]["list"]
    rows = influxql(influx, "crisgeo", _macros(ann["query"]))
    assert [v[1] for v in rows[0]["values"]] == ["EP V116 uploaded"]
    assert rows[0]["values"][0][0] == int(dt.datetime(2025, 2, 10, 6, tzinfo=UTC).timestamp())
    assert influxql(influx, "crisgeo", _macros(ann["query"], satellite="npp")) == []


def test_every_query_names_the_measurement_and_the_satellite(dashboard):
    queries = [t["query"] for p in dashboard["panels"] for t in p["targets"]] + \
              [a["query"] for a in dashboard["annotations"]["list"]]
    for q in queries:
        assert re.search(r'FROM "cris_geolocation(_change)?"', q) and "/^$satellite$/" in q and "$timeFilter" in q
