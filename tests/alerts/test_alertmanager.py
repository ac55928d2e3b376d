"""The Alertmanager channel against a real Alertmanager: the service's alerts arrive with their labels, are
routed to a receiver, and are resolved there when they resolve in the service."""

import datetime as dt
import json
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import pytest
import requests

from alerts.alertmanager import post_state
from alerts.rules import Finding
from alerts.settings import load_alert_settings
from monitor.store.alerts import AlertState
from monitor.store.sqlite import Store
from tests.servers import alertmanager, wait_for

pytestmark = pytest.mark.servers  # starts real servers, daemons or tools (see pyproject markers)


class Receiver:
    """A webhook receiver for Alertmanager's notifications."""

    def __init__(self):
        self.notifications = []
        box = self

        class H(BaseHTTPRequestHandler):
            def log_message(self, *a):
                pass

            def do_POST(self):
                box.notifications.append(json.loads(self.rfile.read(int(self.headers["Content-Length"]))))
                self.send_response(200)
                self.send_header("Content-Length", "0")
                self.end_headers()

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), H)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}/hook"
        threading.Thread(target=self.httpd.serve_forever, daemon=True).start()

    def statuses(self):
        return [n["status"] for n in self.notifications]


@pytest.fixture
def receiver():
    r = Receiver()
    yield r
    r.httpd.shutdown()
    r.httpd.server_close()


def test_alerts_are_posted_routed_and_resolved(tmp_path, receiver):
    now = dt.datetime.now(dt.timezone.utc)
    with alertmanager(tmp_path / "am", receiver.url) as am, Store(tmp_path / "s.sqlite") as store:
        settings = load_alert_settings(
            {"alertmanager": {"url": am}}, tmp_path, dashboard_url="http://grafana/d/x"
        )
        state = AlertState(store)
        finding = Finding("spec", "j01", "critical", "FOR 1 error 1.9 km > 1.5 km", ["FOR 1: 1.9 km"])
        state.upsert(finding, "firing", now, True)
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
        assert wait_for(lambda: "firing" in receiver.statuses(), 30), receiver.notifications
        # posted again (hourly, after every run): still one alert, one notification
        assert post_state(store, settings) == 1
        assert len(requests.get(am + "/api/v2/alerts", timeout=10).json()) == 1
        resolved = dt.datetime.now(dt.timezone.utc)
        state.resolve(finding.fingerprint, resolved)
        assert post_state(store, settings, resolved) == 1
        assert wait_for(lambda: "resolved" in receiver.statuses(), 30), receiver.notifications
        active = requests.get(am + "/api/v2/alerts", params={"active": "true"}, timeout=10).json()
        assert active == []
        assert receiver.statuses().count("firing") == 1


def test_an_unreachable_alertmanager_costs_nothing_but_a_warning(tmp_path, caplog):
    with Store(tmp_path / "s.sqlite") as store:
        settings = load_alert_settings(
            {"alertmanager": {"url": "http://127.0.0.1:9", "timeout_s": 2}}, tmp_path
        )
        AlertState(store).upsert(
            Finding("stale", "j01", "warning", "no run for 30 h"),
            "firing",
            dt.datetime.now(dt.timezone.utc),
            True,
        )
        assert post_state(store, settings) is None
    assert "posted again at the next evaluation" in caplog.text
