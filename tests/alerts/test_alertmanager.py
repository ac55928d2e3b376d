"""The Alertmanager channel against a real Alertmanager: the service's alerts arrive with their labels, are
routed to a receiver, and are resolved there when they resolve in the service."""

import datetime as dt

import pytest
import requests

from alerts.alertmanager import post_state
from alerts.rules import Finding
from benchmarks.servers import Webhook, alertmanager, wait_for
from monitor.config.alert_settings import AlertSettings, Links
from monitor.service.store.alert_state import AlertState
from monitor.service.store.sqlite import Store


@pytest.fixture
def receiver():
    """Alertmanager's webhook receiver: the notifications it gets, in order."""
    r = Webhook("/hook")
    yield r
    r.close()


def statuses(receiver) -> list:
    return [n["status"] for n in receiver.received]


@pytest.mark.servers
def test_alerts_are_posted_routed_and_resolved(tmp_path, receiver):
    now = dt.datetime.now(dt.timezone.utc)
    with alertmanager(tmp_path / "am", receiver.url) as am, Store(tmp_path / "s.sqlite") as store:
        settings = AlertSettings.model_validate({"alertmanager": {"url": am}}).linked(
            Links(dashboard_url="http://grafana/d/x")
        )
        state = AlertState(store)
        finding = Finding("spec", "j01", "critical", "FOR 1 error 1.9 km > 1.5 km", ["FOR 1: 1.9 km"])
        state.upsert(finding, now, True)
        assert post_state(store, settings, now) == 1
        (alert,) = requests.get(am + "/api/v2/alerts", timeout=10).json()
        assert alert["labels"] == {
            "alertname": "crisgeo_spec",
            "service": "crisgeo",
            "satellite": "j01",
            "rule": "spec",
            "severity": "critical",
        }
        assert alert["annotations"]["summary"] == "FOR 1 error 1.9 km > 1.5 km"
        assert alert["status"]["state"] == "active" and alert["generatorURL"] == "http://grafana/d/x"
        assert wait_for(lambda: "firing" in statuses(receiver), 30), receiver.received
        # posted again (hourly, after every run): still one alert, one notification
        assert post_state(store, settings) == 1
        assert len(requests.get(am + "/api/v2/alerts", timeout=10).json()) == 1
        resolved = dt.datetime.now(dt.timezone.utc)
        state.resolve(finding.alert_id, resolved)
        assert post_state(store, settings, resolved) == 1
        assert wait_for(lambda: "resolved" in statuses(receiver), 30), receiver.received
        active = requests.get(am + "/api/v2/alerts", params={"active": "true"}, timeout=10).json()
        assert active == []
        assert statuses(receiver).count("firing") == 1


def test_an_unreachable_alertmanager_costs_nothing_but_a_warning(tmp_path, caplog):
    with Store(tmp_path / "s.sqlite") as store:
        settings = AlertSettings.model_validate(
            {"alertmanager": {"url": "http://127.0.0.1:9", "timeout_s": 2.0}}
        )
        AlertState(store).upsert(
            Finding("stale", "j01", "warning", "no run for 30 h"),
            dt.datetime.now(dt.timezone.utc),
            True,
        )
        assert post_state(store, settings) is None
    assert "posted again at the next evaluation" in caplog.text
