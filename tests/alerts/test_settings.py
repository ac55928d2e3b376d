"""The alerts section of the configuration: defaults once, every problem named by its key."""

from pathlib import Path

import pytest

from alerts.rules import RuleSettings
from alerts.settings import AlertConfigError, EmailSettings, SlackSettings, load_alert_settings

BASE = Path("/etc/crisgeo")


def test_empty_section_gives_the_rule_defaults_and_no_channel():
    s = load_alert_settings({}, BASE)
    assert s.rules == RuleSettings() and s.channels == []


def test_channel_defaults_come_from_their_dataclasses():
    s = load_alert_settings(
        {
            "email": {"host": "smtp.example.org", "to": ["a@example.org"]},
            "slack": {"webhook_env": "HOOK"},
            "log": "alerts.log",
        },
        BASE,
    )
    d = EmailSettings(host="x")
    assert (s.email.port, s.email.sender, s.email.starttls, s.email.timeout_s) == (
        d.port,
        d.sender,
        d.starttls,
        d.timeout_s,
    )
    assert s.slack.retries == SlackSettings("x").retries and s.log == BASE / "alerts.log"
    assert s.channels == ["log", "email", "slack"]


@pytest.mark.parametrize(
    "doc, message",
    [
        ({"spec_km": 0}, "alerts.spec_km: 0.0 is not within"),
        ({"pre_days": 5, "min_pre_days": 7}, "alerts.min_pre_days: 7 is more than alerts.pre_days"),
        ({"jump_z": "high"}, "alerts.jump_z: expected float"),
        ({"spec_kms": 1.0}, "alerts.spec_kms: unknown key"),
        ({"email": {"to": ["a@example.org"]}}, "alerts.email.host: missing"),
        ({"email": {"host": "h", "to": "a@example.org"}}, "alerts.email.to: a list of addresses"),
        ({"email": {"host": "h", "to": ["a@b"], "port": 70000}}, "alerts.email.port: 70000 is not within"),
        (
            {"email": {"host": "h", "to": ["a@b"], "from": "nobody"}},
            "alerts.email.from: 'nobody' is not an address",
        ),
        ({"slack": {"retries": 2}}, "alerts.slack.webhook_env: missing"),
        (
            {"slack": {"webhook_env": "H", "max_wait_s": float("nan")}},
            "alerts.slack.max_wait_s: nan is not a finite",
        ),
    ],
)
def test_problems_name_the_key(doc, message):
    with pytest.raises(AlertConfigError, match=message.replace("(", r"\(").replace(".", r"\.")):
        load_alert_settings(doc, BASE)
