"""The ``alerts`` section of the configuration, validated; secrets come from environment variables."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from urllib.parse import urlsplit

from alerts.rules import RuleSettings


class AlertConfigError(ValueError):
    """A problem in the alerts section, naming the key."""


@dataclass
class EmailSettings:
    """The ``alerts.email`` section."""

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
    """The ``alerts.slack`` section."""

    webhook_env: str
    retries: int = 3
    max_wait_s: float = 30.0
    timeout_s: float = 15.0


@dataclass
class AlertmanagerSettings:
    """The ``alerts.alertmanager`` section: where the service posts its alerts (Alertmanager API v2)."""

    url: str
    timeout_s: float = 10.0
    validity_hours: float = 3.0  # a firing alert not posted again within this ends by itself


@dataclass
class AlertSettings:
    """The ``alerts`` section, validated."""

    rules: RuleSettings
    log: Path | None = None
    email: EmailSettings | None = None
    slack: SlackSettings | None = None
    alertmanager: AlertmanagerSettings | None = None
    events_file: Path | None = None
    report_dir: Path | None = None
    dashboard_url: str | None = None
    report_url: str | None = None  # where readers of the messages open report_dir (e.g. behind a proxy)

    @property
    def channels(self) -> list[str]:
        """The names of the configured channels."""
        return [n for n in ("log", "email", "slack") if getattr(self, n)]


# the keys of the alerts section; email "from" is EmailSettings.sender
ALERT_KEYS = set(RuleSettings.__dataclass_fields__) | {"log", "email", "slack", "alertmanager", "events_file"}
ALERTMANAGER_KEYS = set(AlertmanagerSettings.__dataclass_fields__)
EMAIL_KEYS = {"host", "port", "from", "to", "starttls", "username_env", "password_env", "cafile", "timeout_s"}
SLACK_KEYS = set(SlackSettings.__dataclass_fields__)

RULE_LIMITS = {  # the accepted range of each rule setting, in its unit
    "spec_km": (0.01, 100.0),
    "min_jump_km": (0.001, 100.0),
    "jump_z": (1.0, 100.0),
    "jump_z_at_change": (1.0, 100.0),
    "pre_days": (2, 365),
    "min_pre_days": (2, 365),
    "min_post_days": (1, 365),
    "post_days": (1, 365),
    "blind_window_days": (1, 365),
    "change_window_days": (1, 3650),
    "attribution_days": (0, 365),
    "active_days": (1, 3650),
    "stale_hours": (1.0, 8760.0),
    "repeat_hours": (0.1, 8760.0),
}


def _typed(doc, key, typ, where, default, limits=None):
    v = doc.get(key, default)
    if v is None:
        return None
    if typ is float and isinstance(v, int) and not isinstance(v, bool):
        v = float(v)
    if not isinstance(v, typ) or (typ in (int, float) and isinstance(v, bool)):
        raise AlertConfigError(f"{where}{key}: expected {typ.__name__}, got {str(v)[:60]!r}")
    if typ is float and not math.isfinite(v):
        raise AlertConfigError(f"{where}{key}: {v} is not a finite number")
    if typ is str and "\x00" in v:
        raise AlertConfigError(f"{where}{key}: contains a NUL character")
    if limits is not None and not limits[0] <= v <= limits[1]:
        raise AlertConfigError(f"{where}{key}: {v} is not within {limits[0]:g}..{limits[1]:g}")
    return v


def _mapping(doc, key):
    v = doc.get(key)
    if not isinstance(v, dict):
        raise AlertConfigError(f"alerts.{key}: expected a mapping, got {str(v)[:60]!r}")
    return v


def _only(doc, allowed, where):
    unknown = sorted(set(map(str, doc)) - set(allowed))
    if unknown:
        raise AlertConfigError(f"{where}{unknown[0]}: unknown key")


def load_alert_settings(
    doc: dict, base: Path, report_dir=None, dashboard_url=None, report_url=None
) -> AlertSettings:
    """Parse the alerts section *doc*; relative paths are relative to *base* (the config file's folder)."""
    doc = doc or {}
    if not isinstance(doc, dict):
        raise AlertConfigError("alerts: expected a mapping")
    rules = RuleSettings()
    for key, limits in RULE_LIMITS.items():
        typ = float if isinstance(getattr(rules, key), float) else int
        setattr(rules, key, _typed(doc, key, typ, "alerts.", getattr(rules, key), limits))
    if rules.min_pre_days > rules.pre_days:
        raise AlertConfigError(
            f"alerts.min_pre_days: {rules.min_pre_days} is more than alerts.pre_days ({rules.pre_days})"
        )
    _only(doc, ALERT_KEYS, "alerts.")

    def path(key, d=doc, where="alerts."):
        p = _typed(d, key, str, where, None)
        if p is None or p == "":
            return None
        p = Path(os.path.expandvars(p)).expanduser()
        return p if p.is_absolute() else base / p

    s = AlertSettings(rules=rules, report_dir=report_dir, dashboard_url=dashboard_url, report_url=report_url)
    s.log = path("log")
    s.events_file = path("events_file")
    if s.events_file is not None and not s.events_file.is_file():
        # read as empty, a missing calendar would lose jump attribution without a word
        raise AlertConfigError(
            f"alerts.events_file: {s.events_file} does not exist (copy configs/events.yaml there, or "
            "remove the key)"
        )
    if doc.get("email"):
        e = _mapping(doc, "email")
        w = "alerts.email."
        _only(e, EMAIL_KEYS, w)
        if not _typed(e, "host", str, w, None):
            raise AlertConfigError("alerts.email.host: missing")
        to = e.get("to") or []
        if not isinstance(to, list) or not to or not all(isinstance(a, str) and "@" in a for a in to):
            raise AlertConfigError("alerts.email.to: a list of addresses is needed")
        d = EmailSettings(host=e["host"], to=list(to))  # the defaults, once
        sender = _typed(e, "from", str, w, d.sender)
        if "@" not in sender:
            raise AlertConfigError(f"alerts.email.from: {sender!r} is not an address")
        s.email = EmailSettings(
            host=e["host"],
            port=_typed(e, "port", int, w, d.port, (1, 65535)),
            sender=sender,
            to=list(to),
            starttls=_typed(e, "starttls", bool, w, d.starttls),
            username_env=_typed(e, "username_env", str, w, d.username_env),
            password_env=_typed(e, "password_env", str, w, d.password_env),
            cafile=str(path("cafile", e, w)) if e.get("cafile") else None,
            timeout_s=_typed(e, "timeout_s", float, w, d.timeout_s, (0.1, 600.0)),
        )
    if doc.get("slack"):
        sl = _mapping(doc, "slack")
        w = "alerts.slack."
        _only(sl, SLACK_KEYS, w)
        if not sl.get("webhook_env"):
            raise AlertConfigError(
                "alerts.slack.webhook_env: missing (the name of the variable holding the URL)"
            )
        ds = SlackSettings(webhook_env=sl["webhook_env"])
        s.slack = SlackSettings(
            webhook_env=_typed(sl, "webhook_env", str, w, None),
            retries=_typed(sl, "retries", int, w, ds.retries, (0, 20)),
            max_wait_s=_typed(sl, "max_wait_s", float, w, ds.max_wait_s, (0.0, 3600.0)),
            timeout_s=_typed(sl, "timeout_s", float, w, ds.timeout_s, (0.1, 600.0)),
        )
    if doc.get("alertmanager"):
        am = _mapping(doc, "alertmanager")
        w = "alerts.alertmanager."
        _only(am, ALERTMANAGER_KEYS, w)
        url = _typed(am, "url", str, w, None)
        parts = urlsplit(url or "")
        if parts.scheme not in ("http", "https") or not parts.netloc or "@" in parts.netloc:
            raise AlertConfigError(
                f"{w}url: {url!r} is not an http(s) URL without credentials (e.g. http://127.0.0.1:9093)"
            )
        da = AlertmanagerSettings(url=url)
        s.alertmanager = AlertmanagerSettings(
            url=url.rstrip("/"),
            timeout_s=_typed(am, "timeout_s", float, w, da.timeout_s, (0.1, 600.0)),
            validity_hours=_typed(am, "validity_hours", float, w, da.validity_hours, (1.5, 168.0)),
        )
    return s


def secret(name: str | None) -> str | None:
    """The value of the environment variable *name*, or None."""
    return os.environ.get(name) if name else None
