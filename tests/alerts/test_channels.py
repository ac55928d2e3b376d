import dataclasses
import email

import pytest

from alerts.channels import EmailChannel, Permanent, SlackChannel, Transient
from monitor.config.alert_settings import EmailSettings, SlackSettings
from monitor.history.records import Attachment, Message
from tests.alerts.conftest import PASSWORD, USER
from tests.invoke import run_crisgeo

MSG = Message(
    "[crisgeo] j01 CRITICAL: 1 firing - spec",
    "FOR 30: total 4.51 km\nspec 1.5 km",
    "<pre>FOR 30: total 4.51 km</pre>",
    ("*FIRING spec*\nFOR 30 <4.5 km> & more",),
)


def _email(port, cafile, **kw):
    return EmailSettings(
        host="localhost",
        port=port,
        sender="crisgeo@test",
        to=["sdr@test"],
        cafile=cafile,
        username_env="T_SMTP_USER",
        password_env="T_SMTP_PASS",
        timeout_s=10,
        **kw,
    )


@pytest.mark.servers
def test_email_over_starttls_with_login_arrives_intact_once(smtp_server, monkeypatch, tmp_path):
    inbox, port, cafile = smtp_server
    monkeypatch.setenv("T_SMTP_USER", USER)
    monkeypatch.setenv("T_SMTP_PASS", PASSWORD)
    png = Attachment("trend.png", b"\x89PNG\r\n\x1a\n" + b"0" * 100)
    EmailChannel(_email(port, cafile)).send(dataclasses.replace(MSG, attachments=(png,)))
    assert len(inbox.messages) == 1
    env = inbox.messages[0]
    assert env.mail_from == "crisgeo@test" and env.rcpt_tos == ["sdr@test"]
    m = email.message_from_bytes(env.content)
    assert m["Subject"] == MSG.subject
    parts = {p.get_content_type(): p for p in m.walk()}
    assert parts["text/plain"].get_payload(decode=True).decode().replace("\r\n", "\n").strip() == MSG.text
    assert "<pre>" in parts["text/html"].get_payload(decode=True).decode()
    assert parts["image/png"].get_payload(decode=True) == png.content
    assert parts["image/png"].get_filename() == "trend.png"
    assert PASSWORD.encode() not in env.content


@pytest.mark.servers
def test_email_wrong_password_is_permanent_and_untrusted_cert_refused(smtp_server, monkeypatch):
    inbox, port, cafile = smtp_server
    monkeypatch.setenv("T_SMTP_USER", USER)
    monkeypatch.setenv("T_SMTP_PASS", "wrong")
    with pytest.raises(Permanent, match="login refused"):
        EmailChannel(_email(port, cafile)).send(MSG)
    monkeypatch.setenv("T_SMTP_PASS", PASSWORD)
    with pytest.raises(Permanent, match="TLS"):
        EmailChannel(_email(port, None)).send(MSG)  # the system CA store does not know the test certificate
    assert inbox.messages == []


def test_email_server_down_is_transient():
    with pytest.raises(Transient):
        EmailChannel(_email(1, None)).send(MSG)


def _slack(monkeypatch, url, **kw):
    monkeypatch.setenv("T_SLACK", url)
    sleeps = []
    return SlackChannel(SlackSettings(webhook_env="T_SLACK", timeout_s=5, **kw), sleep=sleeps.append), sleeps


@pytest.mark.servers
def test_slack_ok(webhook, monkeypatch):
    ch, _ = _slack(monkeypatch, webhook.url)
    ch.send(MSG)
    (payload,) = webhook.received
    assert payload["text"].startswith("FOR 30") and payload["blocks"][0]["text"]["type"] == "mrkdwn"


@pytest.mark.servers
def test_slack_429_honours_retry_after(webhook, monkeypatch):
    ch, sleeps = _slack(monkeypatch, webhook.url)
    webhook.script = [(429, "rate_limited", {"Retry-After": "2"})]
    ch.send(MSG)
    assert sleeps == [2.0] and len(webhook.received) == 2
    webhook.script = [(429, "rate_limited", {"Retry-After": "120"})]
    with pytest.raises(Transient) as e:
        ch.send(MSG)
    assert e.value.retry_after_s == 120.0


@pytest.mark.servers
def test_slack_5xx_retried_with_backoff_then_transient(webhook, monkeypatch):
    ch, sleeps = _slack(monkeypatch, webhook.url, retries=2)
    webhook.script = [(500, "rollup_error", {}), (503, "", {})]
    ch.send(MSG)
    assert sleeps == [1.0, 2.0] and len(webhook.received) == 3
    webhook.script = [(500, "", {})] * 3
    with pytest.raises(Transient, match="500"):
        ch.send(MSG)


@pytest.mark.servers
def test_slack_4xx_is_a_configuration_error_without_the_url(webhook, monkeypatch):
    ch, _ = _slack(monkeypatch, webhook.url)
    webhook.script = [(404, "channel_not_found", {})]
    with pytest.raises(Permanent) as e:
        ch.send(MSG)
    assert "channel_not_found" in str(e.value) and "secret-token" not in str(e.value)
    assert len(webhook.received) == 1


@pytest.mark.servers
def test_concurrent_deliveries_send_a_message_once(webhook, tmp_path, monkeypatch):
    """Two processes' deliverers on one store (two connections, two threads) race for the same queued
    message; the claim lets exactly one post it, even though the webhook answers slowly."""
    import datetime as dt
    import threading

    from alerts.engine import deliver
    from monitor.config.alert_settings import AlertSettings
    from monitor.service.store.alert_state import AlertState
    from monitor.service.store.sqlite import Store

    monkeypatch.setenv("T_SLACK", webhook.url)
    settings = AlertSettings(slack=SlackSettings(webhook_env="T_SLACK", timeout_s=5))
    path = tmp_path / "s.sqlite"
    now = dt.datetime(2026, 1, 1, tzinfo=dt.timezone.utc)
    store = Store(path)
    AlertState(store).enqueue("slack", "j01", Message("s", "t", ""), now)
    store.close()
    both_saw_it = threading.Barrier(2, timeout=30)
    real_due = AlertState.due

    def due_for_both(self, when):
        """Both deliverers read the queue, and find the message due, before either goes on to claim it."""
        found = real_due(self, when)
        both_saw_it.wait()
        return found

    monkeypatch.setattr(AlertState, "due", due_for_both)
    counts = []

    def run():
        s = Store(path)
        counts.append(deliver(s, settings, now=now))
        s.close()

    threads = [threading.Thread(target=run) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(webhook.received) == 1 and sorted(c.sent for c in counts) == [0, 1]
    s = Store(path)
    assert [d.status for d in AlertState(s).deliveries()] == ["sent"]


@pytest.mark.servers
def test_verbose_logs_never_show_the_webhook(webhook, tmp_path):
    """`crisgeo -v` logs at debug level; urllib3's request lines (which carry the webhook's secret path)
    are kept out."""
    import datetime as dt
    import os

    from monitor.service.store.alert_state import AlertState
    from monitor.service.store.sqlite import Store

    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        f"alerts: {{slack: {{webhook_env: T_SLACK}}}}\n"
    )
    (tmp_path / "state").mkdir()
    store = Store(tmp_path / "state" / "crisgeo.sqlite")
    AlertState(store).enqueue(
        "slack",
        "j01",
        Message("s", "t", ""),
        dt.datetime.now(dt.timezone.utc) - dt.timedelta(minutes=1),
    )
    store.close()
    r = run_crisgeo("-v", "alerts", "evaluate", "--config", cfg, env={**os.environ, "T_SLACK": webhook.url})
    assert r.returncode == 0, r.stderr
    assert len(webhook.received) >= 1  # it was sent
    assert "secret-token" not in r.stderr + r.stdout and "DEBUG" in r.stderr
