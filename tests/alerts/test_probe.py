"""``crisgeo alerts test``: a marked test message through real SMTP, webhook and Alertmanager servers,
reported per channel, leaving the store, the alert log and the alert state untouched."""

import datetime as dt
import email
from email import policy

import pytest
import requests

from benchmarks.servers import Webhook, alertmanager
from monitor.cli import main
from tests.alerts.conftest import PASSWORD, USER

pytestmark = pytest.mark.servers  # starts real servers (see pyproject markers)


def _config(tmp_path, port, cafile, am=None):
    cfg = tmp_path / "c.yaml"
    extra = f"\n  alertmanager: {{url: '{am}'}}" if am else ""
    cfg.write_text(f"""satellites: [j01]
state_dir: {tmp_path / "state"}
source: {{kind: simulated}}
alerts:
  log: {tmp_path / "alerts.log"}
  email: {{host: localhost, port: {port}, from: crisgeo@test, to: [sdr@test], cafile: {cafile},
           username_env: T_SMTP_USER, password_env: T_SMTP_PASS}}
  slack: {{webhook_env: T_HOOK, retries: 0}}{extra}
""")
    return cfg


def test_each_channel_reports_delivered_or_why_not_and_nothing_is_kept(
    smtp_server, webhook, monkeypatch, tmp_path, capsys
):
    inbox, port, cafile = smtp_server
    monkeypatch.setenv("T_SMTP_USER", USER)
    monkeypatch.setenv("T_SMTP_PASS", PASSWORD)
    monkeypatch.setenv("T_HOOK", webhook.url)
    receiver = Webhook("/am")
    try:
        with alertmanager(tmp_path / "am", receiver.url) as am:
            cfg = _config(tmp_path, port, cafile, am)
            assert main(["alerts", "test", "--config", str(cfg)]) == 0
            assert capsys.readouterr().out.splitlines() == [
                "email: delivered",
                "slack: delivered",
                "alertmanager: delivered",
            ]
            (alert,) = requests.get(am + "/api/v2/alerts", timeout=10).json()
            assert alert["labels"]["test"] == "true" and alert["labels"]["alertname"] == "crisgeo_test"
            ends = dt.datetime.fromisoformat(alert["endsAt"].replace("Z", "+00:00"))
            assert ends - dt.datetime.now(dt.timezone.utc) <= dt.timedelta(minutes=5)
    finally:
        receiver.close()
    (m,) = [email.message_from_bytes(x.content, policy=policy.default) for x in inbox.messages]
    assert (
        "TEST notification" in m["Subject"] and "nothing needs doing" in m.get_body(("plain",)).get_content()
    )
    assert webhook.received[0]["text"].startswith("TEST:")
    # no store, no alert log: nothing of the service's state was touched
    assert not (tmp_path / "state" / "crisgeo.sqlite").exists() and not (tmp_path / "alerts.log").exists()

    # one channel, refused: its reason, exit 1; a channel not configured is bad input
    webhook.script = [(404, "no_service", {})]
    assert main(["alerts", "test", "--config", str(cfg), "--channel", "slack"]) == 1
    assert capsys.readouterr().out.strip() == (
        "slack: not delivered: Slack HTTP 404 'no_service': check the webhook configuration"
    )
    assert len(inbox.messages) == 1
    bare = tmp_path / "bare.yaml"
    bare.write_text(f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: simulated}}\n")
    assert main(["alerts", "test", "--config", str(bare), "--channel", "alertmanager"]) == 2
    assert "channel 'alertmanager' is not configured (configured: none)" in capsys.readouterr().err


def test_evaluate_says_what_the_repeat_interval_holds_back(tmp_path, capsys):
    """A failure alert notified two hours ago: evaluating again within repeat_hours sends nothing and says
    why."""
    from alerts.rules import Finding
    from monitor.service.store.alert_state import AlertState
    from monitor.service.store.sqlite import Store

    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: simulated}}\n"
        f"alerts: {{log: {tmp_path / 'alerts.log'}}}\n"
    )
    with Store(tmp_path / "state" / "crisgeo.sqlite") as store:
        sent = dt.datetime.now(dt.timezone.utc) - dt.timedelta(hours=2)
        AlertState(store).upsert(Finding("failure", "j01", "critical", "1 failed run"), sent, True)
        store.finish_run(store.begin_run("j01", dt.date(2026, 1, 1)), "failed", "HTTP 503")
    assert main(["alerts", "evaluate", "--config", str(cfg)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("queued 0, sent 0") and "not sent again within the repeat interval" in out
    assert f"failure:j01 (sent {sent:%Y-%m-%d %H:%M}, again from" in out
