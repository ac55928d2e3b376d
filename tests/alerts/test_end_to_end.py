"""The daily job with alerts to a real SMTP server and a real webhook: fire once, stay quiet, resolve."""

import datetime as dt
import email
import json
from email import policy

import pytest

from monitor.config.file import load_config
from monitor.service.daemon import Service
from monitor.simulate.case import simulate_case
from tests.alerts.conftest import PASSWORD, USER

pytestmark = pytest.mark.servers  # starts real servers, daemons or tools (see pyproject markers)

DAY1, DAY2 = dt.date(2024, 6, 1), dt.date(2024, 6, 2)


@pytest.fixture(scope="module")
def two_days(cases, tmp_path_factory):
    paper, _, _ = cases.get("paper", 1)
    fixed = tmp_path_factory.mktemp("corrected")
    simulate_case(
        fixed, granules=2, profile="zero", seed=1, start=dt.datetime(2024, 6, 2, 12, tzinfo=dt.timezone.utc)
    )
    data = tmp_path_factory.mktemp("data")
    for d in (paper, fixed):
        for f in d.glob("*.h5"):
            (data / f.name).symlink_to(f)
    return data


def test_fire_once_then_quiet_then_resolved(two_days, smtp_server, webhook, monkeypatch, tmp_path):
    inbox, port, cafile = smtp_server
    monkeypatch.setenv("T_SMTP_USER", USER)
    monkeypatch.setenv("T_SMTP_PASS", PASSWORD)
    monkeypatch.setenv("T_HOOK", webhook.url)
    cfg_path = tmp_path / "c.yaml"
    cfg_path.write_text(f"""satellites: [j01]
state_dir: {tmp_path / "state"}
source: {{kind: local, path: {two_days}}}
assessment: {{workers: 1}}
dashboard_url: http://grafana.test/d/crisgeo
report_dir: {tmp_path / "report"}
report_url: https://crisgeo.test/report/
alerts:
  log: {tmp_path / "alerts.log"}
  email: {{host: localhost, port: {port}, from: crisgeo@test, to: [sdr@test], cafile: {cafile},
           username_env: T_SMTP_USER, password_env: T_SMTP_PASS}}
  slack: {{webhook_env: T_HOOK}}
""")
    service = Service(load_config(cfg_path))
    assert service.run("j01", DAY1).status == "ok"
    assert len(inbox.messages) == 1 and len(webhook.received) == 1
    m = email.message_from_bytes(inbox.messages[0].content, policy=policy.default)
    assert "CRITICAL" in m["Subject"] and "spec" in m["Subject"]
    body = m.get_body(("plain",)).get_content()
    for k in (27, 28, 29, 30):
        assert f"FOR {k}:" in body
    assert "FOR 15:" not in body and "http://grafana.test/d/crisgeo" in body and "granule pair(s)" in body
    assert "report: https://crisgeo.test/report/j01/" in body and str(tmp_path) not in body
    assert "FOR 30" in webhook.received[0]["text"]
    assert "https://crisgeo.test/report/j01/" in json.dumps(webhook.received[0])
    # the report, regenerated after the evaluation, shows the alert; the e-mail carries the trend plot,
    # handed to the engine as data (drawn from the store, not read from the report's folder)
    assert "FOR 30" in (tmp_path / "report" / "j01" / "index.html").read_text()
    (plot,) = m.iter_attachments()
    assert plot.get_filename() == "trend.png" and plot.get_content().startswith(b"\x89PNG")
    assert webhook.url not in (tmp_path / "alerts.log").read_text()

    assert service.run("j01", DAY1).status == "ok"  # the same day again: nothing new
    assert len(inbox.messages) == 1 and len(webhook.received) == 1

    assert service.run("j01", DAY2).status == "ok"  # corrected geolocation
    assert len(inbox.messages) == 2 and len(webhook.received) == 2
    m2 = email.message_from_bytes(inbox.messages[1].content, policy=policy.default)
    body2 = m2.get_body(("plain",)).get_content()
    assert "1 resolved" in m2["Subject"] and "RESOLVED spec" in body2
    # the corrected GEO has another LOS fingerprint: the same message announces the processing change
    assert "FIRING processing" in body2 and "CrIS geolocation processing changed" in body2
    page = (tmp_path / "report" / "j01" / "index.html").read_text()
    assert "2 day(s) shown" in page and "CrIS geolocation processing changed" in page


def test_channel_down_gets_the_message_later(two_days, webhook, monkeypatch, tmp_path):
    from alerts.engine import deliver
    from monitor.service.store.alert_state import AlertState
    from monitor.service.store.sqlite import Store

    monkeypatch.setenv("T_HOOK", webhook.url)
    cfg_path = tmp_path / "c.yaml"
    cfg_path.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\n"
        f"source: {{kind: local, path: {two_days}}}\nassessment: {{workers: 1}}\n"
        "alerts: {slack: {webhook_env: T_HOOK, retries: 0}}\n"
    )
    webhook.script = [(503, "", {})]
    service = Service(load_config(cfg_path))
    service.run("j01", DAY1)
    assert len(webhook.received) == 1
    store = Store(service.cfg.store.sqlite)
    (pending,) = AlertState(store).deliveries("pending")
    assert "503" in pending.last_error
    later = dt.datetime.now(dt.timezone.utc) + dt.timedelta(hours=2)
    assert deliver(store, service.cfg.alerts, later).sent == 1
    assert deliver(store, service.cfg.alerts, later).sent == 0  # not twice
    assert len(webhook.received) == 2 and webhook.received[0] == webhook.received[1]
