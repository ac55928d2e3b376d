"""The ``alerts`` section of the configuration, validated; secrets come from environment variables."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from alerts.rules import RuleSettings


class AlertConfigError(ValueError):
    """A problem in the alerts section, naming the key."""


@dataclass
class EmailSettings:
    host: str
    port: int = 587
    sender: str = "crisgeo@localhost"
    to: list = field(default_factory=list)
    starttls: bool = True
    username_env: str | None = None
    password_env: str | None = None
    cafile: str | None = None  # extra CA bundle (e.g. a site CA); the system store otherwise
    timeout_s: float = 30.0


@dataclass
class SlackSettings:
    webhook_env: str
    retries: int = 3
    max_wait_s: float = 30.0
    timeout_s: float = 15.0


@dataclass
class AlertSettings:
    rules: RuleSettings
    log: Path | None = None
    email: EmailSettings | None = None
    slack: SlackSettings | None = None
    events_file: Path | None = None
    report_dir: Path | None = None
    dashboard_url: str | None = None

    @property
    def channels(self) -> list[str]:
        return [n for n in ("log", "email", "slack") if getattr(self, n)]


def _typed(doc, key, typ, where, default):
    v = doc.get(key, default)
    if v is None:
        return None
    if typ is float and isinstance(v, int) and not isinstance(v, bool):
        v = float(v)
    if not isinstance(v, typ):
        raise AlertConfigError(f"{where}{key}: expected {typ.__name__}, got {v!r}")
    return v


def load_alert_settings(doc: dict, base: Path, report_dir=None, dashboard_url=None) -> AlertSettings:
    """Parse the alerts section *doc*; relative paths are relative to *base* (the config file's folder)."""
    doc = doc or {}
    rules = RuleSettings()
    for key in ("spec_km", "min_jump_km", "stale_hours", "repeat_hours", "jump_z", "jump_z_at_change"):
        setattr(rules, key, _typed(doc, key, float, "alerts.", getattr(rules, key)))
    for key in ("pre_days", "min_pre_days", "min_post_days", "post_days", "blind_window_days", "attribution_days",
                "active_days", "change_window_days"):
        setattr(rules, key, _typed(doc, key, int, "alerts.", getattr(rules, key)))
    allowed = set(RuleSettings.__dataclass_fields__) | {"log", "email", "slack", "events_file"}
    unknown = sorted(set(doc) - allowed)
    if unknown:
        raise AlertConfigError(f"alerts.{unknown[0]}: unknown key")

    def path(p):
        p = Path(os.path.expandvars(str(p))).expanduser()
        return p if p.is_absolute() else base / p

    s = AlertSettings(rules=rules, report_dir=report_dir, dashboard_url=dashboard_url)
    if doc.get("log"):
        s.log = path(doc["log"])
    if doc.get("events_file"):
        s.events_file = path(doc["events_file"])
    if doc.get("email"):
        e = doc["email"]
        if not isinstance(e, dict) or not e.get("host"):
            raise AlertConfigError("alerts.email.host: missing")
        to = e.get("to") or []
        if not isinstance(to, list) or not to:
            raise AlertConfigError("alerts.email.to: a list of addresses is needed")
        s.email = EmailSettings(host=e["host"], port=int(e.get("port", 587)), sender=e.get("from", "crisgeo@localhost"),
                                to=list(to), starttls=bool(e.get("starttls", True)),
                                username_env=e.get("username_env"), password_env=e.get("password_env"),
                                cafile=str(path(e["cafile"])) if e.get("cafile") else None,
                                timeout_s=float(e.get("timeout_s", 30.0)))
    if doc.get("slack"):
        sl = doc["slack"]
        if not isinstance(sl, dict) or not sl.get("webhook_env"):
            raise AlertConfigError("alerts.slack.webhook_env: missing (the name of the variable holding the URL)")
        s.slack = SlackSettings(webhook_env=sl["webhook_env"], retries=int(sl.get("retries", 3)),
                                max_wait_s=float(sl.get("max_wait_s", 30.0)), timeout_s=float(sl.get("timeout_s", 15.0)))
    return s


def secret(name: str | None) -> str | None:
    return os.environ.get(name) if name else None
