"""The configuration reference: every key the loader accepts, with its default, unit, range and meaning.

Keys, defaults and ranges come from the configuration model (:mod:`monitor.config`, :mod:`alerts.settings`,
:class:`alerts.rules.RuleSettings`); only the meanings are written here. ``crisgeo check-config
--reference`` prints it; ``docs/configuration.md`` is its output, and a test keeps both equal and
complete.
"""

from __future__ import annotations

import dataclasses
import datetime as dt
from pathlib import Path

from alerts.rules import RuleSettings
from alerts.settings import (
    ALERT_KEYS,
    ALERTMANAGER_KEYS,
    EMAIL_KEYS,
    RULE_LIMITS,
    SLACK_KEYS,
    AlertmanagerSettings,
    EmailSettings,
    SlackSettings,
)
from monitor import config as C

MEANING = {
    "satellites": "Satellites to monitor, short names (npp, j01, j02). Required.",
    "state_dir": "Directory of the service's state: store, download cache, simulated granules, lock. "
    "Required; relative paths in the file are relative to the file.",
    "report_dir": "Where the HTML report is regenerated after every run (and served under /report/). None: "
    "no report.",
    "report_url": "The address at which readers open report_dir (e.g. behind a reverse proxy); messages link"
    " REPORT_URL/SATELLITE/. Without it they name the path on the server.",
    "dashboard_url": "Link to the Grafana dashboard, added to every message.",
    "source.kind": "Where granules come from: nodd (NOAA's archive on S3), local (a directory tree) or "
    "simulated (the offline demo). Required.",
    "source.path": "Root of the local tree (kind local); every *.h5 below it is considered.",
    "source.endpoint": "NODD URL template; {bucket} is replaced by the satellite's bucket.",
    "source.buckets": "NODD bucket per satellite (mapping); keys not given keep the published buckets.",
    "source.timeout_s": "Wall-clock bound of a listing page (body included) and of the headers of any "
    "answer; also the socket timeout.",
    "source.retries": "Retries of a failed request (backoff doubling from backoff_s).",
    "source.backoff_s": "First wait between retries.",
    "source.daily_budget_mb": "Most bytes downloaded in one satellite-day run; further files are skipped "
    "with the reason.",
    "source.retention_days": "Downloaded files older than this are removed from the cache at the start of a "
    "run (kind simulated: this many simulated days are kept).",
    "source.cache_max_mb": "Before every run the least recently used downloads go until the cache holds at"
    " most this (a run adds at most daily_budget_mb).",
    "source.run_deadline_min": "Every request of one satellite-day run ends by this time after the run "
    "started.",
    "source.max_list_pages": "Most pages of one listing (a day of one product is ~3 pages of 1000 keys).",
    "source.max_listed_keys": "Most keys of one listing.",
    "source.max_retry_after_s": "A server asking to wait longer than this (Retry-After) ends the attempt.",
    "source.min_rate_kb_s": "A download that brings less than this over any stall_window_s is cut (and "
    "retried).",
    "source.stall_window_s": "The sliding window over which a download must keep up min_rate_kb_s; a "
    "silence this long cuts it too.",
    "source.granules": "Consecutive CrIS granules simulated per satellite-day (kind simulated).",
    "source.profile": "Error profile injected by the simulator (paper, random, zero; kind simulated).",
    "source.seed": "Seed of the simulator (kind simulated).",
    "schedule.time_utc": "Time of the daily run, HH:MM UTC.",
    "schedule.catch_up_days": "Days back (ending lag_days ago) that are assessed when they have no completed"
    " run.",
    "schedule.misfire_grace_hours": "A daily run missed by less than this (e.g. host asleep) still runs.",
    "schedule.lag_days": "The daily run assesses the day that ended this many days ago (archive latency).",
    "schedule.no_data_retry_days": "A day found empty is tried again for this many days after it is due, "
    "then recorded as no_data_final.",
    "schedule.run_budget_min": "A satellite-day run longer than this makes /healthz unhealthy and stops "
    "feeding the systemd watchdog (a restart follows). Keep it above "
    "source.run_deadline_min.",
    "scenes.candidates": "CrIS granules of the day scored for inhomogeneity (spread over the day).",
    "scenes.keep": "Most inhomogeneous granules assessed (the paper uses 14).",
    "scenes.min_inhomogeneity_k": "A granule whose VIIRS-BT spread is below this is not used.",
    "assessment.half_steps": "Perturbations on each side of zero per direction: the grid is (2n+1)^2 (21 x "
    "21).",
    "assessment.step_urad": "Perturbation step (375 m at nadir from 833 km); half_steps^2 x step_urad <= "
    "200000.",
    "assessment.kernel": "CrIS footprint weighting: top-hat (the paper) or response (measured FOV response).",
    "assessment.workers": "Threads of the compiled VIIRS preparation and collocation kernels.",
    "fingerprint.granules": "GEO granules per day sampled (spread over the day) for the LOS fingerprint.",
    "fingerprint.threshold_urad": "A FOR whose fingerprint angle moves more than this is a processing "
    "change.",
    "fingerprint.ep_library": "EP files or directories to identify the EP in use from; empty: the packaged "
    "real EPs.",
    "http.listen": "HOST:PORT of /metrics, /healthz and /report/ (loopback by default; port 0: any free "
    "port; off: no endpoint). crisgeo daemon --listen overrides it.",
    "store.sqlite": "The SQLite store (history, alert state, outbox). Default: state_dir/crisgeo.sqlite.",
    "store.drain_minutes": "The daemon sends the time-series points waiting in the outbox this often.",
    "store.publish": "Time-series databases the results are written to (list of the mappings below).",
    "store.publish[].kind": "influx2 (InfluxDB 2 API: token) or influx1 (InfluxDB 1 / VictoriaMetrics: user,"
    " password). Required.",
    "store.publish[].url": "Base URL of the database (no credentials in it). Required.",
    "store.publish[].measurement": "Measurement name of the points.",
    "store.publish[].bucket": "Bucket (influx2).",
    "store.publish[].org": "Organisation (influx2).",
    "store.publish[].token_env": "Environment variable holding the token (influx2).",
    "store.publish[].database": "Database (influx1).",
    "store.publish[].username_env": "Environment variable holding the user name (influx1).",
    "store.publish[].password_env": "Environment variable holding the password (influx1).",
    "store.publish[].timeout_s": "Timeout of one write.",
    "alerts.spec_km": "Specification of the geolocation error on the ground; a reliable FOR beyond it fires "
    "the spec rule (critical when value - 2 sigma is beyond it).",
    "alerts.min_jump_km": "Smallest step (median after minus median before) that counts as a jump.",
    "alerts.jump_z": "Step size in units of its standard error that counts as a jump, on any day of the "
    "recent window (blind search).",
    "alerts.jump_z_at_change": "The same at the date of a known change (events calendar, fingerprint).",
    "alerts.pre_days": "Days before a candidate step that form the reference.",
    "alerts.min_pre_days": "Fewest assessed days before a step for the test to run.",
    "alerts.post_days": "Days after a candidate step compared with the reference.",
    "alerts.min_post_days": "Fewest assessed days after a step for the test to run.",
    "alerts.blind_window_days": "Recent days tried as step dates without a known change.",
    "alerts.change_window_days": "Known changes this recent are tried as step dates.",
    "alerts.attribution_days": "A jump is attributed to a known change at most this many days before it.",
    "alerts.active_days": "A jump or processing change older than this no longer fires.",
    "alerts.stale_hours": "No completed run for this long fires the stale rule.",
    "alerts.repeat_hours": "A firing alert is notified again after this long.",
    "alerts.log": "File the alert messages are appended to (a channel that cannot fail).",
    "alerts.events_file": "The events calendar (EP uploads, LUT changes) used to attribute jumps and "
    "annotate plots.",
    "alerts.email": "E-mail channel (mapping below); absent: none.",
    "alerts.email.host": "SMTP server. Required.",
    "alerts.email.port": "SMTP port.",
    "alerts.email.from": "Sender address.",
    "alerts.email.to": "Recipient addresses (list). Required.",
    "alerts.email.starttls": "Use STARTTLS (certificate verified against the system store, or cafile).",
    "alerts.email.username_env": "Environment variable holding the SMTP user name.",
    "alerts.email.password_env": "Environment variable holding the SMTP password.",
    "alerts.email.cafile": "Extra CA bundle (e.g. a site CA) to verify the server with.",
    "alerts.email.timeout_s": "Timeout of one SMTP conversation.",
    "alerts.slack": "Slack channel (mapping below); absent: none.",
    "alerts.alertmanager": "Alertmanager (mapping below): the alerts are posted to its API v2 with labels "
    "alertname, service, satellite, rule, severity and resolved there, so that Alertmanager routes, "
    "groups and silences them; absent: none.",
    "alerts.alertmanager.url": "Base URL of Alertmanager, e.g. http://127.0.0.1:9093. Required.",
    "alerts.alertmanager.timeout_s": "Timeout of one post.",
    "alerts.alertmanager.validity_hours": "A firing alert is posted again at every evaluation (hourly, "
    "and after each run) with this end; if the service stops posting, Alertmanager ends it then.",
    "alerts.slack.webhook_env": "Environment variable holding the incoming-webhook URL. Required.",
    "alerts.slack.retries": "Retries when Slack answers 429 or 5xx.",
    "alerts.slack.max_wait_s": "Longest wait honoured from a Retry-After header.",
    "alerts.slack.timeout_s": "Timeout of one request.",
}

UNITS = (
    ("_kb_s", "kB/s"),
    ("_urad", "µrad"),
    ("_km", "km"),
    ("_k", "K"),
    ("_mb", "MB"),
    ("_min", "min"),
    ("_minutes", "min"),
    ("_hours", "h"),
    ("_days", "days"),
    ("_s", "s"),
)
REQUIRED = {
    "satellites",
    "state_dir",
    "source.kind",
    "store.publish[].kind",
    "store.publish[].url",
    "alerts.email.host",
    "alerts.email.to",
    "alerts.slack.webhook_env",
}
_ALERT_LIMITS = {
    "alerts.email.port": (1, 65535),
    "alerts.email.timeout_s": (0.1, 600.0),
    "alerts.slack.retries": (0, 20),
    "alerts.slack.max_wait_s": (0.0, 3600.0),
    "alerts.slack.timeout_s": (0.1, 600.0),
    "alerts.alertmanager.timeout_s": (0.1, 600.0),
    "alerts.alertmanager.validity_hours": (1.5, 168.0),
    "store.publish[].timeout_s": (0.1, 600),
}


def _default(cls, name):
    f = cls.__dataclass_fields__[name]
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return None


def model_keys() -> dict:
    """{key: default} for every key the loader accepts (mappings and lists are keys themselves)."""
    keys = {k: None for k in C.TOP_KEYS - set(C.SECTIONS) - {"store", "alerts"}}
    for section, cls in C.SECTIONS.items():
        keys.update({f"{section}.{f.name}": _default(cls, f.name) for f in dataclasses.fields(cls)})
    keys.update({f"store.{k}": _default(C.StoreConfig, k) if k != "sqlite" else None for k in C.STORE_KEYS})
    keys.update(
        {f"store.publish[].{k}": _default(C.PublishConfig, k) for k in C.PublishConfig.__dataclass_fields__}
    )
    for k in ALERT_KEYS:
        keys[f"alerts.{k}"] = _default(RuleSettings, k) if k in RuleSettings.__dataclass_fields__ else None
    keys.update(
        {f"alerts.email.{k}": _default(EmailSettings, "sender" if k == "from" else k) for k in EMAIL_KEYS}
    )
    keys.update({f"alerts.slack.{k}": _default(SlackSettings, k) for k in SLACK_KEYS})
    keys.update({f"alerts.alertmanager.{k}": _default(AlertmanagerSettings, k) for k in ALERTMANAGER_KEYS})
    return keys


def _show(v) -> str:
    if v is None or v == () or v == []:
        return ""
    if isinstance(v, dt.time):
        return v.strftime("%H:%M")
    if isinstance(v, dict):
        return ", ".join(f"{k}: {x}" for k, x in v.items())
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, (Path, str)):
        return str(v)
    return str(v).lower() if isinstance(v, bool) else str(v)


def _unit(key: str) -> str:
    name = key.rsplit(".", 1)[-1]
    return next((u for suffix, u in UNITS if name.endswith(suffix)), "")


def _range(key: str) -> str:
    lo_hi = C.LIMITS.get(key) or _ALERT_LIMITS.get(key)
    if lo_hi is None and key.startswith("alerts."):
        lo_hi = RULE_LIMITS.get(key.split(".", 1)[1])
    num = lambda v: str(v) if isinstance(v, int) else f"{v:g}"  # noqa: E731
    return "" if lo_hi is None else f"{num(lo_hi[0])} .. {num(lo_hi[1])}"


def reference() -> str:
    """The reference as Markdown: one table, keys in file order of their sections."""
    keys = model_keys()
    order = ["", "source", "schedule", "scenes", "assessment", "fingerprint", "http", "store", "alerts"]
    rank = lambda k: (order.index(k.split(".")[0]) if "." in k else 0, k.count("."), k)  # noqa: E731
    lines = [
        "# Configuration reference",
        "",
        "Generated by `crisgeo check-config --reference` from the configuration model; "
        "`crisgeo check-config --config FILE` validates a file and prints it with every default filled in.",
        "Relative paths are relative to the configuration file. Keys ending in `_env` name an environment "
        "variable holding a secret; secrets are never written in the file.",
        "",
        "| key | default | unit | range | meaning |",
        "|---|---|---|---|---|",
    ]
    for key in sorted(keys, key=rank):
        default = "(required)" if key in REQUIRED else _show(keys[key])
        lines.append(f"| `{key}` | {default} | {_unit(key)} | {_range(key)} | {MEANING[key]} |")
    return "\n".join(lines) + "\n"
