"""The dashboard for Prometheus-only sites: every panel's PromQL, run by VictoriaMetrics (PromQL) on scrapes
of the daemon's /metrics over a store of assessed days, gives the stored numbers; its service-health row is
the InfluxDB dashboard's, panel for panel."""

import datetime as dt
import json
import time
from pathlib import Path

import pytest
import requests

from benchmarks.servers import victoria_metrics, wait_for
from monitor.service.store.sqlite import Store
from monitor.simulate.history import fill_store

pytestmark = pytest.mark.servers  # starts real servers, daemons or tools (see pyproject markers)

GRAFANA = Path(__file__).resolve().parents[2] / "configs" / "grafana"
PROMETHEUS = json.loads((GRAFANA / "crisgeo-prometheus-dashboard.json").read_text())
INFLUX = json.loads((GRAFANA / "crisgeo-dashboard.json").read_text())


def _expr(expr: str) -> str:
    """The query as Grafana sends it for satellite j01 and FORs 01, 15, 30."""
    return expr.replace('=~"$satellite"', '=~"j01"').replace('=~"$for"', '=~"01|15|30"')


def test_the_health_row_is_the_influx_dashboards_and_no_panel_needs_influxdb():
    health = lambda d: [p for p in d["panels"] if p.get("datasource", {}).get("type") == "prometheus" and  # noqa: E731
                        "crisgeo_for_" not in json.dumps(p.get("targets"))]  # fmt: skip
    assert health(PROMETHEUS) == health(INFLUX) and len(health(INFLUX)) == 5
    text = json.dumps(PROMETHEUS)
    assert "influx" not in text.lower() and PROMETHEUS["uid"] != INFLUX["uid"]
    assert PROMETHEUS["__inputs"] == [] and {r["id"] for r in PROMETHEUS["__requires"]} >= {"prometheus"}


def test_every_panel_gives_the_stored_numbers(tmp_path):
    from prometheus_client import generate_latest

    from monitor.service.health import Health
    from monitor.service.outputs.metrics import ServiceMetrics

    db = tmp_path / "s.sqlite"
    with Store(db) as store:
        days = fill_store(store, ["j01", "npp"], dt.date.today() - dt.timedelta(days=3), 3, step_day=2)
        fors = store.day_result("j01", days[-1])
    metrics = ServiceMetrics(lambda: Store(db), ["j01", "npp"], Health(300), "test", 1.5)
    now = int(time.time())
    with victoria_metrics(tmp_path / "vm") as url:
        text = generate_latest(metrics.registry).decode()
        for t in (now - 7200, now - 60):  # two scrapes
            r = requests.post(url + "/api/v1/import/prometheus", params={"timestamp": t * 1000}, data=text,
                              timeout=10)  # fmt: skip
            assert r.status_code == 204, r.text
        requests.get(url + "/internal/force_flush", timeout=10)

        def query(expr):
            r = requests.get(url + "/api/v1/query", params={"query": _expr(expr), "time": now}, timeout=10)
            assert r.json()["status"] == "success", (expr, r.text)
            return {x["metric"].get("for"): float(x["value"][1]) for x in r.json()["data"]["result"]}

        assert wait_for(lambda: query("crisgeo_for_reliable"), 30)
        # the variables: satellites and FORs, as Grafana's label_values asks for them
        sats = requests.get(url + "/api/v1/label/satellite/values", timeout=10).json()["data"]
        assert {"j01", "npp"} <= set(sats)
        match = {"match[]": 'crisgeo_for_offset_meters{satellite=~"j01"}'}
        labels = requests.get(url + "/api/v1/label/for/values", params=match, timeout=10).json()["data"]
        assert labels == [f"{k:02d}" for k in range(1, 31)]
        reliable = {f"{f.for_index:02d}": f for f in fors if f.reliable}
        flagged = {f"{f.for_index:02d}" for f in fors if not f.reliable}
        checked = 0
        for panel in [p for p in PROMETHEUS["panels"] if "crisgeo_for_" in json.dumps(p.get("targets"))]:
            title = panel["title"]
            for target in panel["targets"]:
                got = query(target["expr"])
                if title.startswith("Flagged"):
                    assert set(got) == flagged, title
                    continue
                direction = "in_track" if "in_track" in target["expr"] else "cross_track"
                chosen = {"01", "15", "30"} if "chosen" in title else None
                shown = set(reliable) if "reliable" in target["expr"] else {f"{k:02d}" for k in range(1, 31)}
                assert set(got) == (shown & chosen if chosen else shown), title
                for k, value in got.items():
                    f = next(x for x in fors if f"{x.for_index:02d}" == k)
                    assert value == pytest.approx(getattr(f, f"{direction}_km"), abs=1e-9), (title, k)
                    checked += 1
        assert checked == 2 * len(reliable) + 2 * len({"01", "15", "30"} & set(reliable)) + 2 * 30
