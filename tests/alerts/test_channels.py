import email
import smtplib

import pytest

from alerts.channels import EmailChannel, Permanent, SlackChannel, Transient
from alerts.settings import EmailSettings, SlackSettings
from tests.alerts.conftest import PASSWORD, USER

MSG = {"subject": "[crisgeo] j01 CRITICAL: 1 firing - spec", "text": "FOR 30: total 4.51 km\nspec 1.5 km",
       "html": "<pre>FOR 30: total 4.51 km</pre>", "blocks": ["*FIRING spec*\nFOR 30 <4.5 km> & more"],
       "attachments": []}


def _email(port, cafile, **kw):
    return EmailSettings(host="localhost", port=port, sender="crisgeo@test", to=["sdr@test"], cafile=cafile,
                         username_env="T_SMTP_USER", password_env="T_SMTP_PASS", timeout_s=10, **kw)


def test_email_over_starttls_with_login_arrives_intact_once(smtp_server, monkeypatch, tmp_path):
    inbox, port, cafile = smtp_server
    monkeypatch.setenv("T_SMTP_USER", USER)
    monkeypatch.setenv("T_SMTP_PASS", PASSWORD)
    png = tmp_path / "trend.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n" + b"0" * 100)
    EmailChannel(_email(port, cafile)).send(dict(MSG, attachments=[str(png)]))
    assert len(inbox.messages) == 1
    env = inbox.messages[0]
    assert env.mail_from == "crisgeo@test" and env.rcpt_tos == ["sdr@test"]
    m = email.message_from_bytes(env.content)
    assert m["Subject"] == MSG["subject"]
    parts = {p.get_content_type(): p for p in m.walk()}
    assert parts["text/plain"].get_payload(decode=True).decode().replace("\r\n", "\n").strip() == MSG["text"]
    assert "<pre>" in parts["text/html"].get_payload(decode=True).decode()
    assert parts["image/png"].get_payload(decode=True) == png.read_bytes()
    assert PASSWORD.encode() not in env.content


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


def test_slack_ok(webhook, monkeypatch):
    ch, _ = _slack(monkeypatch, webhook.url)
    ch.send(MSG)
    (payload,) = webhook.received
    assert payload["text"].startswith("FOR 30") and payload["blocks"][0]["text"]["type"] == "mrkdwn"


def test_slack_429_honours_retry_after(webhook, monkeypatch):
    ch, sleeps = _slack(monkeypatch, webhook.url)
    webhook.script = [(429, "rate_limited", {"Retry-After": "2"})]
    ch.send(MSG)
    assert sleeps == [2.0] and len(webhook.received) == 2
    webhook.script = [(429, "rate_limited", {"Retry-After": "120"})]
    with pytest.raises(Transient) as e:
        ch.send(MSG)
    assert e.value.retry_after_s == 120.0


def test_slack_5xx_retried_with_backoff_then_transient(webhook, monkeypatch):
    ch, sleeps = _slack(monkeypatch, webhook.url, retries=2)
    webhook.script = [(500, "rollup_error", {}), (503, "", {})]
    ch.send(MSG)
    assert sleeps == [1.0, 2.0] and len(webhook.received) == 3
    webhook.script = [(500, "", {})] * 3
    with pytest.raises(Transient, match="500"):
        ch.send(MSG)


def test_slack_4xx_is_a_configuration_error_without_the_url(webhook, monkeypatch):
    ch, _ = _slack(monkeypatch, webhook.url)
    webhook.script = [(404, "channel_not_found", {})]
    with pytest.raises(Permanent) as e:
        ch.send(MSG)
    assert "channel_not_found" in str(e.value) and "secret-token" not in str(e.value)
    assert len(webhook.received) == 1
