"""The dashboard the alerts link to exists; the file carries what Grafana's import dialog reads."""

import json
from pathlib import Path
from urllib.parse import urlsplit

import yaml

ROOT = Path(__file__).resolve().parents[2]
DASHBOARD = json.loads((ROOT / "configs" / "grafana" / "crisgeo-dashboard.json").read_text())


def test_the_shipped_dashboard_url_opens_the_shipped_dashboard():
    url = yaml.safe_load((ROOT / "configs" / "monitor.yaml").read_text())["dashboard_url"]
    assert urlsplit(url).path.split("/")[2] == DASHBOARD["uid"]


def test_the_dashboard_declares_what_it_requires():
    assert DASHBOARD["__inputs"] == []  # its data sources are variables, chosen on the dashboard
    required = {(r["type"], r["id"]) for r in DASHBOARD["__requires"]}
    assert {("grafana", "grafana"), ("datasource", "influxdb"), ("datasource", "prometheus")} <= required
    panels = {p["type"] for p in DASHBOARD["panels"]} - {"row"}
    assert panels <= {i for t, i in required if t == "panel"}
