"""The alerts section of the configuration: defaults once (the model's), every problem named by its key."""

import pytest
import yaml

from monitor.config.alert_settings import AlertSettings, EmailSettings, RuleSettings, SlackSettings
from monitor.config.file import load_config
from monitor.config.keys import ConfigError


def _load(tmp_path, alerts):
    p = tmp_path / "c.yaml"
    p.write_text(
        yaml.safe_dump(
            {"satellites": ["j01"], "state_dir": "s", "source": {"kind": "simulated"}, "alerts": alerts}
        )
    )
    return load_config(p)


def test_empty_section_gives_the_rule_defaults_and_no_channel(tmp_path):
    s = _load(tmp_path, {}).alerts
    assert RuleSettings.model_validate(s.model_dump(include=set(RuleSettings.model_fields))) == RuleSettings()
    assert s.channels == [] and s == AlertSettings()


def test_channel_defaults_come_from_the_model(tmp_path):
    s = _load(
        tmp_path,
        {
            "email": {"host": "smtp.example.org", "to": ["a@example.org"]},
            "slack": {"webhook_env": "HOOK"},
            "log": "alerts.log",
        },
    ).alerts
    d = EmailSettings(host="x", to=["a@b"])
    assert (s.email.port, s.email.sender, s.email.starttls, s.email.timeout_s) == (
        d.port,
        d.sender,
        d.starttls,
        d.timeout_s,
    )
    assert s.slack.retries == SlackSettings(webhook_env="x").retries and s.log == tmp_path / "alerts.log"
    assert s.channels == ["log", "email", "slack"]


@pytest.mark.parametrize(
    "doc, message",
    [
        ({"spec_km": 0}, "alerts.spec_km: 0 is not within 0.01..100"),
        ({"pre_days": 5, "min_pre_days": 7}, "alerts.min_pre_days: 7 is more than alerts.pre_days (5)"),
        (
            {"false_detections_per_year": "high"},
            "alerts.false_detections_per_year: expected float, got str 'high'",
        ),
        ({"spec_kms": 1.0}, "alerts.spec_kms: unknown key"),
        ({"email": {"to": ["a@example.org"]}}, "alerts.email.host: missing"),
        ({"email": {"host": "h", "to": "a@example.org"}}, "alerts.email.to: expected list"),
        ({"email": {"host": "h", "to": []}}, "alerts.email.to: empty"),
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
        (
            {"alertmanager": {"url": "127.0.0.1:9093"}},
            "alerts.alertmanager.url: '127.0.0.1:9093' is not an http",
        ),
    ],
)
def test_problems_name_the_key(tmp_path, doc, message):
    with pytest.raises(ConfigError) as exc:
        _load(tmp_path, doc)
    assert str(exc.value).startswith(message), str(exc.value)


def test_the_subject_prefix_marks_every_message(tmp_path):
    """A key added to the model (one declaration) is loaded, documented and used: a test instance's
    messages say so in their subject."""
    from alerts.engine import build_message
    from alerts.rules import Finding
    from monitor.config.reference import reference
    from monitor.service.store.sqlite import Store

    assert "| `alerts.subject_prefix` | [crisgeo] |" in reference()
    settings = _load(tmp_path, {"subject_prefix": "[crisgeo test]"}).alerts
    finding = Finding("stale", "j01", "warning", "no successful assessment for 40 h")
    with Store(tmp_path / "s.sqlite") as store:
        message = build_message(store, "j01", [("firing", finding)], settings)
        assert message.subject.startswith("[crisgeo test] j01 WARNING")
        default = build_message(store, "j01", [("firing", finding)], AlertSettings())
        assert default.subject.startswith("[crisgeo] j01")
