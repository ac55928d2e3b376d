"""The service configuration: one YAML file, validated on load; secrets only from the environment.

Every error names the key and the problem (``ConfigError: store.publish[0].url: missing``). Keys whose
value is a secret end in ``_env`` and hold the *name* of an environment variable, never the secret.
"""

from __future__ import annotations

import datetime as dt
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import urlsplit, urlunsplit

import yaml
import yaml.events

from monitor.constants import DEFAULT_HALF_STEPS, DEFAULT_STEP_URAD, MAX_GRID_SPREAD_RAD, URAD
from monitor.satellites import SATELLITES

if TYPE_CHECKING:
    from alerts.settings import AlertSettings

NODD_BUCKETS = {s.short: s.bucket for s in SATELLITES.values()}


class ConfigError(ValueError):
    """A configuration problem, naming the key."""


@dataclass
class SourceConfig:
    """The ``source`` section (docs/configuration.md)."""

    kind: str  # simulated | local | nodd
    path: Path | None = None
    endpoint: str = "https://{bucket}.s3.amazonaws.com"
    buckets: dict = field(default_factory=lambda: dict(NODD_BUCKETS))
    timeout_s: float = 60.0
    retries: int = 5
    backoff_s: float = 1.5
    daily_budget_mb: float = 6000.0
    retention_days: int = 7
    cache_max_mb: float = 20000.0  # the download cache is cut to this before every run (LRU)
    run_deadline_min: float = 180.0  # every request of one satellite-day's run ends by then
    max_list_pages: int = 100  # per listing (a day of one product is ~3 pages of 1000 keys)
    max_listed_keys: int = 20000
    max_retry_after_s: float = 120.0  # a server asking to wait longer ends the attempt
    min_rate_kb_s: float = 50.0  # a download slower than this over any stall window is cut
    stall_window_s: float = 30.0
    granules: int = 4
    profile: str = "paper"
    seed: int = 0


@dataclass
class ScheduleConfig:
    """The ``schedule`` section."""

    time_utc: dt.time = dt.time(3, 30)
    catch_up_days: int = 7
    misfire_grace_hours: float = 6.0
    lag_days: int = 1  # assess the day that ended this many days ago
    no_data_retry_days: int = 3  # a day found empty is tried again this many days, then recorded as final
    run_budget_min: float = 240.0  # a satellite-day run longer than this makes the daemon unhealthy


@dataclass
class SceneConfig:
    """The ``scenes`` section."""

    candidates: int = 40
    keep: int = 14
    min_inhomogeneity_k: float = 0.5


@dataclass
class FingerprintConfig:
    """The ``fingerprint`` section."""

    granules: int = 100  # GEO granules per day, spread over the day
    threshold_urad: float = 10.0
    ep_library: tuple = ()  # EP files/directories to identify the EP from; empty: the packaged real EPs


@dataclass
class AssessmentConfig:
    """The ``assessment`` section."""

    half_steps: int = DEFAULT_HALF_STEPS
    step_urad: float = DEFAULT_STEP_URAD
    kernel: str = "top-hat"
    workers: int = 2


@dataclass
class PublishConfig:
    """One entry of ``store.publish``."""

    kind: str  # influx2 | influx1
    url: str
    measurement: str = "cris_geolocation"
    bucket: str = "crisgeo"
    org: str = "-"
    token_env: str | None = None
    database: str = "crisgeo"
    username_env: str | None = None
    password_env: str | None = None
    timeout_s: float = 30.0

    def secret(self, key: str) -> str | None:
        """The value of the environment variable named by *key* (e.g. token_env), or None."""
        name = getattr(self, key)
        return os.environ.get(name) if name else None


@dataclass
class HttpConfig:
    """The ``http`` section."""

    listen: str = (
        "127.0.0.1:9782"  # HOST:PORT of /metrics, /healthz, /report/ ("off": none; port 0: any free)
    )


@dataclass
class StoreConfig:
    """The ``store`` section."""

    sqlite: Path
    publish: list = field(default_factory=list)
    drain_minutes: float = 10.0  # the daemon sends what waits in the outbox this often, between daily runs


@dataclass
class Config:
    """The whole configuration, validated; ``alert_settings`` is its alerts section parsed."""

    path: Path
    satellites: list
    state_dir: Path
    source: SourceConfig
    schedule: ScheduleConfig
    scenes: SceneConfig
    assessment: AssessmentConfig
    store: StoreConfig
    alerts: dict = field(default_factory=dict)
    fingerprint: FingerprintConfig = field(default_factory=FingerprintConfig)
    http: HttpConfig = field(default_factory=HttpConfig)
    report_dir: Path | None = None
    report_url: str | None = None
    dashboard_url: str | None = None
    alert_settings: AlertSettings | None = None  # parsed and validated with the rest

    @property
    def events_file(self) -> Path | None:
        """The events calendar (``alerts.events_file``): attribution of jumps, annotations, the report."""
        return self.alert_settings.events_file if self.alert_settings else None

    @property
    def cache_dir(self) -> Path:
        """Where downloads are cached: ``state_dir/cache``."""
        return self.state_dir / "cache"


TOP_KEYS = {
    "satellites",
    "state_dir",
    "source",
    "schedule",
    "scenes",
    "assessment",
    "store",
    "alerts",
    "fingerprint",
    "http",
    "report_dir",
    "report_url",
    "dashboard_url",
}
SECTIONS = {
    "source": SourceConfig,
    "schedule": ScheduleConfig,
    "scenes": SceneConfig,
    "assessment": AssessmentConfig,
    "fingerprint": FingerprintConfig,
    "http": HttpConfig,
}
STORE_KEYS = {"sqlite", "publish", "drain_minutes"}


def _get(doc: dict, key: str, typ, where: str, default=None, required=False):
    if key not in doc or doc[key] is None:
        if required:
            raise ConfigError(f"{where}{key}: missing")
        return default
    value = doc[key]
    if typ is float and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if not isinstance(value, typ) or (typ in (int, float) and isinstance(value, bool)):
        raise ConfigError(
            f"{where}{key}: expected {typ.__name__}, got {type(value).__name__} {str(value)[:60]!r}"
        )
    if typ is float and not math.isfinite(value):
        raise ConfigError(f"{where}{key}: {value} is not a finite number")
    if typ is str and "\x00" in value:
        raise ConfigError(f"{where}{key}: contains a NUL character")
    return value


def _check_creatable(path: Path, where: str) -> None:
    """*path* is a directory, or can be made one: its nearest existing ancestor is a writable directory
    on a file system that holds files (not /proc or /sys). Nothing is created."""
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe == path and not path.is_dir():
        raise ConfigError(f"{where}: {path} exists and is not a directory")
    if not probe.is_dir() or not os.access(probe, os.W_OK | os.X_OK):
        raise ConfigError(f"{where}: {path} cannot be created ({probe} is not a writable directory)")
    if probe != path and os.statvfs(probe).f_blocks == 0:  # proc, sysfs and the like: no room for files
        raise ConfigError(f"{where}: {path} cannot be created ({probe} is a virtual file system)")


def make_state_dir(cfg: Config) -> None:
    """Create the state directory (for the commands that write state); a ConfigError naming the key."""
    try:
        cfg.state_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"state_dir: cannot create {cfg.state_dir} ({exc.strerror or exc})") from None


def _within(value, lo, hi, where):
    """*value* within lo..hi (inclusive), or a ConfigError naming the key."""
    if not lo <= value <= hi:
        raise ConfigError(f"{where}: {value} is not within {lo:g}..{hi:g}")
    return value


def _fill(obj, doc: dict, where: str, **types):
    """Set each named field of the section dataclass *obj* from *doc*, checking its type; the default is
    the dataclass's own (one default per key). Ranges are checked afterwards (:data:`LIMITS`)."""
    for name, typ in types.items():
        setattr(obj, name, _get(doc, name, typ, where, getattr(obj, name)))
    return obj


def _known(doc: dict, allowed: set, where: str):
    unknown = sorted(str(k) for k in doc if k not in allowed)  # keys may be of any YAML type
    if unknown:
        raise ConfigError(f"{where}{unknown[0]}: unknown key (allowed: {', '.join(sorted(allowed))})")


def _section(doc, key):
    value = doc.get(key)
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise ConfigError(f"{key}: expected a mapping, got {type(value).__name__} {str(value)[:60]!r}")
    return value


SECRET_WORDS = re.compile(r"(token|password|secret|webhook)$", re.I)


def _check_secrets(doc, where=""):
    """No secret written in the file (a key named like one), and every *_env value the name of an
    environment variable (an identifier, not a secret pasted in)."""
    if isinstance(doc, dict):
        for k, v in doc.items():
            if SECRET_WORDS.search(str(k)) and v not in (None, ""):
                raise ConfigError(
                    f"{where}{k}: secrets may not be written in the file; "
                    f"name an environment variable with {k}_env"
                )
            if (
                str(k).endswith("_env")
                and v is not None
                and not (isinstance(v, str) and ENV_NAME.fullmatch(v))
            ):
                raise ConfigError(
                    f"{where}{k}: {'a value' if isinstance(v, str) else repr(v)} is not the name "
                    f"of an environment variable"
                )
            _check_secrets(v, f"{where}{k}.")
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            _check_secrets(v, f"{where[:-1]}[{i}].")


MAX_CONFIG_BYTES = 1 << 20
ENV_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,127}", re.ASCII)


class _Loader(yaml.SafeLoader):
    """Safe YAML without anchors and aliases: a configuration needs none, and aliases nest into bombs."""

    def compose_node(self, parent, index):
        if self.check_event(yaml.events.AliasEvent):
            mark = self.peek_event().start_mark
            raise ConfigError(
                f"line {mark.line + 1}: YAML aliases (*name) are not allowed in the configuration"
            )
        event = self.peek_event()
        if getattr(event, "anchor", None):
            raise ConfigError(
                f"line {event.start_mark.line + 1}: YAML anchors (&name) are not allowed in the configuration"
            )
        return super().compose_node(parent, index)

    def construct_mapping(self, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            if isinstance(key, (list, dict)):
                raise ConfigError(f"line {key_node.start_mark.line + 1}: a mapping key must be a scalar")
            if key in seen:
                raise ConfigError(
                    f"line {key_node.start_mark.line + 1}: key {str(key)[:60]!r} is given twice in one "
                    "mapping"
                )
            seen.add(key)
        return super().construct_mapping(node, deep)


def read_yaml(path: Path):
    """The YAML document at *path*: at most 1 MiB, safe types only, no anchors or aliases."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read ({exc.strerror})") from None
    if len(raw) > MAX_CONFIG_BYTES:
        raise ConfigError(f"{path}: larger than {MAX_CONFIG_BYTES >> 20} MiB")
    try:
        return yaml.load(raw.decode("utf-8"), Loader=_Loader)  # noqa: S506 - _Loader is a SafeLoader
    except UnicodeDecodeError:
        raise ConfigError(f"{path}: not UTF-8 text") from None
    except ConfigError as exc:
        raise ConfigError(f"{path}: {exc}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: {yaml_problem(exc)}") from None


def yaml_problem(exc: yaml.YAMLError) -> str:
    """A YAML error as one line: where (line, column) and what."""
    mark = getattr(exc, "problem_mark", None)
    problem = " ".join(str(getattr(exc, "problem", None) or exc).split())[:200]
    where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
    return f"not valid YAML: {where}{problem}"


def check_url(url: str, where: str, placeholder: str | None = None) -> str:
    """An http(s) URL without credentials in it (secrets come from *_env variables)."""
    try:
        parts = urlsplit(url)
    except ValueError:
        raise ConfigError(f"{where}: {url!r} is not a URL") from None
    if parts.scheme not in ("http", "https") or not parts.netloc:
        raise ConfigError(f"{where}: {redact_url(url)!r} is not an http(s) URL")
    if parts.username or parts.password or "@" in parts.netloc:
        raise ConfigError(
            f"{where}: credentials may not be written in a URL; name environment variables "
            f"with the *_env keys"
        )
    if placeholder and placeholder not in url:
        raise ConfigError(f"{where}: {url!r} has no {placeholder} placeholder")
    return url


def check_listen(text: str, where: str) -> str:
    """``off`` or ``HOST:PORT`` (the daemon's HTTP endpoint)."""
    if text == "off":
        return text
    from monitor.endpoint import parse_listen

    try:
        parse_listen(text)
    except ValueError as exc:
        raise ConfigError(f"{where}: {exc} (or off)") from None
    return text


def redact_url(url: str) -> str:
    """*url* with any user:password and query string masked, for logs and messages."""
    try:
        p = urlsplit(str(url))
    except ValueError:
        return "<unparsable URL>"
    netloc = p.netloc.rsplit("@", 1)[-1]
    if "@" in p.netloc:
        netloc = "***@" + netloc
    return urlunsplit((p.scheme, netloc, p.path, "***" if p.query else "", ""))


def load_config(path) -> Config:
    """Load and validate the YAML configuration at *path*, the alerts section included; relative paths are
    relative to the file. Any problem is a :class:`ConfigError` naming the key."""
    path = Path(path)
    doc = read_yaml(path)
    if not isinstance(doc, dict):
        raise ConfigError(f"{path}: expected a mapping at the top level")
    _check_secrets(doc)
    _known(doc, TOP_KEYS, "")
    base = path.resolve().parent

    def rel(p):
        p = Path(os.path.expandvars(p)).expanduser()
        return p if p.is_absolute() else base / p

    sats = _get(doc, "satellites", list, "", required=True)
    for i, s in enumerate(sats):
        if s not in SATELLITES:
            raise ConfigError(f"satellites[{i}]: {s!r} is not one of {', '.join(SATELLITES)}")
    if not sats:
        raise ConfigError("satellites: empty")
    state_dir = rel(_get(doc, "state_dir", str, "", required=True))
    _check_creatable(state_dir, "state_dir")

    s = _section(doc, "source")
    _known(s, set(SourceConfig.__dataclass_fields__), "source.")
    kind = _get(s, "kind", str, "source.", required=True)
    if kind not in ("simulated", "local", "nodd"):
        raise ConfigError(f"source.kind: {kind!r} is not one of simulated, local, nodd")
    source = SourceConfig(kind=kind)
    if kind == "local":
        source.path = rel(_get(s, "path", str, "source.", required=True))
        if not source.path.is_dir():
            raise ConfigError(f"source.path: {source.path} is not a directory")
    _fill(
        source,
        s,
        "source.",
        timeout_s=float,
        backoff_s=float,
        daily_budget_mb=float,
        cache_max_mb=float,
        run_deadline_min=float,
        max_retry_after_s=float,
        min_rate_kb_s=float,
        stall_window_s=float,
        max_list_pages=int,
        max_listed_keys=int,
        retries=int,
        retention_days=int,
        granules=int,
        seed=int,
        profile=str,
        endpoint=str,
    )
    buckets = _get(s, "buckets", dict, "source.", None)
    if buckets:
        for k, v in buckets.items():
            if not isinstance(v, str):
                raise ConfigError(f"source.buckets.{k}: expected a bucket name, got {v!r}")
        source.buckets.update({str(k): v for k, v in buckets.items()})

    sc = _section(doc, "schedule")
    _known(sc, set(ScheduleConfig.__dataclass_fields__), "schedule.")
    schedule = _fill(
        ScheduleConfig(),
        sc,
        "schedule.",
        catch_up_days=int,
        lag_days=int,
        no_data_retry_days=int,
        misfire_grace_hours=float,
        run_budget_min=float,
    )
    t = _get(sc, "time_utc", str, "schedule.", schedule.time_utc.strftime("%H:%M"))
    m = re.fullmatch(r"(\d{1,2}):(\d{2})", t, re.ASCII)
    if not m or int(m[1]) > 23 or int(m[2]) > 59:
        raise ConfigError(f"schedule.time_utc: {t!r} is not HH:MM")
    schedule.time_utc = dt.time(int(m[1]), int(m[2]))

    se = _section(doc, "scenes")
    _known(se, set(SceneConfig.__dataclass_fields__), "scenes.")
    scenes = _fill(SceneConfig(), se, "scenes.", candidates=int, keep=int, min_inhomogeneity_k=float)

    a = _section(doc, "assessment")
    _known(a, set(AssessmentConfig.__dataclass_fields__), "assessment.")
    assessment = _fill(
        AssessmentConfig(), a, "assessment.", half_steps=int, step_urad=float, kernel=str, workers=int
    )
    if assessment.kernel not in ("top-hat", "response"):
        raise ConfigError(f"assessment.kernel: {assessment.kernel!r} is not top-hat or response")

    st = _section(doc, "store")
    _known(st, STORE_KEYS, "store.")
    store = _fill(
        StoreConfig(sqlite=rel(_get(st, "sqlite", str, "store.", str(state_dir / "crisgeo.sqlite")))),
        st,
        "store.",
        drain_minutes=float,
    )
    for i, p in enumerate(_get(st, "publish", list, "store.", [])):
        where = f"store.publish[{i}]."
        if not isinstance(p, dict):
            raise ConfigError(f"{where[:-1]}: expected a mapping")
        _known(p, set(PublishConfig.__dataclass_fields__), where)
        pk = _get(p, "kind", str, where, required=True)
        if pk not in ("influx2", "influx1"):
            raise ConfigError(f"{where}kind: {pk!r} is not influx2 or influx1")
        url = check_url(_get(p, "url", str, where, required=True), f"{where}url")
        store.publish.append(
            _fill(
                PublishConfig(kind=pk, url=url.rstrip("/")),
                p,
                where,
                measurement=str,
                bucket=str,
                org=str,
                database=str,
                token_env=str,
                username_env=str,
                password_env=str,
                timeout_s=float,
            )
        )

    fp = _section(doc, "fingerprint")
    _known(fp, set(FingerprintConfig.__dataclass_fields__), "fingerprint.")
    library = fp.get("ep_library") or []
    if isinstance(library, str):
        library = [library]
    if not isinstance(library, list) or not all(isinstance(x, str) and "\x00" not in x for x in library):
        raise ConfigError(f"fingerprint.ep_library: expected a list of paths, got {library!r}")
    fingerprint = _fill(
        FingerprintConfig(ep_library=tuple(rel(x) for x in library)),
        fp,
        "fingerprint.",
        granules=int,
        threshold_urad=float,
    )
    h = _section(doc, "http")
    _known(h, set(HttpConfig.__dataclass_fields__), "http.")
    http = _fill(HttpConfig(), h, "http.", listen=str)
    check_listen(http.listen, "http.listen")
    alerts = _section(doc, "alerts")
    report_dir = _get(doc, "report_dir", str, "", None)
    report_url, dashboard_url = (_get(doc, k, str, "", None) for k in ("report_url", "dashboard_url"))
    for key, url in (("report_url", report_url), ("dashboard_url", dashboard_url)):
        if url:
            check_url(url, key)
    cfg = Config(
        path=path,
        satellites=list(sats),
        state_dir=state_dir,
        source=source,
        schedule=schedule,
        scenes=scenes,
        assessment=assessment,
        store=store,
        alerts=alerts,
        fingerprint=fingerprint,
        http=http,
        report_dir=rel(report_dir) if report_dir else None,
        report_url=report_url,
        dashboard_url=dashboard_url,
    )
    _check_limits(cfg)
    from alerts.settings import AlertConfigError, load_alert_settings

    try:
        cfg.alert_settings = load_alert_settings(
            alerts, base, cfg.report_dir, cfg.dashboard_url, cfg.report_url
        )
    except AlertConfigError as exc:
        raise ConfigError(str(exc)) from None
    return cfg


# The accepted range of every bounded number: (lowest, highest), in the key's unit.
LIMITS = {
    "source.timeout_s": (0.1, 3600),
    "source.retries": (0, 20),
    "source.backoff_s": (0.01, 600),
    "source.daily_budget_mb": (1, 1e6),
    "source.retention_days": (0, 3650),
    "source.cache_max_mb": (0, 1e8),
    "source.run_deadline_min": (1, 1440),
    "source.max_list_pages": (1, 10000),
    "source.max_listed_keys": (1, 10**6),
    "source.max_retry_after_s": (1, 3600),
    "source.min_rate_kb_s": (1, 1e6),
    "source.stall_window_s": (1, 3600),
    "source.granules": (1, 100),
    "source.seed": (0, 2**31 - 1),
    "schedule.catch_up_days": (1, 366),
    "schedule.lag_days": (0, 30),
    "schedule.no_data_retry_days": (0, 366),
    "schedule.misfire_grace_hours": (0.01, 72),
    "schedule.run_budget_min": (0.01, 10080),
    "scenes.candidates": (1, 1000),
    "scenes.keep": (1, 200),
    "scenes.min_inhomogeneity_k": (0, 50),
    "assessment.half_steps": (1, 40),
    "assessment.step_urad": (10, 5000),
    "assessment.workers": (1, 64),
    "store.drain_minutes": (0.01, 1440),
    "fingerprint.granules": (1, 2000),
    "fingerprint.threshold_urad": (0.1, 10000),
}
BUCKET = re.compile(r"[a-z0-9][a-z0-9.-]{1,61}[a-z0-9]", re.ASCII)


def _check_limits(cfg: Config) -> None:
    for key, (lo, hi) in LIMITS.items():
        section, name = key.split(".")
        _within(getattr(getattr(cfg, section), name), lo, hi, key)
    if cfg.scenes.keep > cfg.scenes.candidates:
        raise ConfigError(
            f"scenes.keep: {cfg.scenes.keep} is more than scenes.candidates ({cfg.scenes.candidates})"
        )
    spread = cfg.assessment.half_steps**2 * cfg.assessment.step_urad * URAD
    if spread > MAX_GRID_SPREAD_RAD:
        raise ConfigError(
            f"assessment.half_steps: {cfg.assessment.half_steps} with step_urad "
            f"{cfg.assessment.step_urad:g}: half_steps^2 x step_urad = {spread / URAD:.0f} urad is more "
            f"than {MAX_GRID_SPREAD_RAD / URAD:.0f} (the widest grid of the compiled collocation)"
        )
    if len(set(cfg.satellites)) != len(cfg.satellites):
        raise ConfigError("satellites: a satellite is listed twice")
    check_url(cfg.source.endpoint, "source.endpoint", "{bucket}")
    for sat, bucket in cfg.source.buckets.items():
        if sat not in SATELLITES:
            raise ConfigError(f"source.buckets.{sat}: not one of {', '.join(SATELLITES)}")
        if not BUCKET.fullmatch(bucket):
            raise ConfigError(f"source.buckets.{sat}: {bucket!r} is not a bucket name")
    for i, p in enumerate(cfg.store.publish):
        _within(p.timeout_s, 0.1, 600, f"store.publish[{i}].timeout_s")


def effective(cfg: Config) -> dict:
    """The configuration as loaded, defaults filled in, under the keys the loader reads: written out as
    YAML it loads back to the same configuration (``crisgeo check-config`` prints it). Secrets are never in
    it: the ``*_env`` keys name variables (see :func:`secret_status`)."""
    import dataclasses

    def plain(v):
        if dataclasses.is_dataclass(v):
            return {f.name: plain(getattr(v, f.name)) for f in dataclasses.fields(v)}
        if isinstance(v, dict):
            return {str(k): plain(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [plain(x) for x in v]
        if isinstance(v, Path):
            return str(v)
        if isinstance(v, dt.time):
            return v.strftime("%H:%M")
        return v

    source = plain(cfg.source)
    if cfg.source.kind != "local":
        source.pop("path")
    out = {
        "satellites": list(cfg.satellites),
        "state_dir": str(cfg.state_dir),
        "source": source,
        "schedule": plain(cfg.schedule),
        "scenes": plain(cfg.scenes),
        "assessment": plain(cfg.assessment),
        "fingerprint": plain(cfg.fingerprint),
        "http": plain(cfg.http),
        "store": {**plain(cfg.store), "publish": [plain(p) for p in cfg.store.publish]},
    }
    for key in ("report_dir", "report_url", "dashboard_url"):
        value = getattr(cfg, key)
        if value is not None:
            out[key] = str(value)
    a = cfg.alert_settings
    if a is None:
        return out
    alerts = plain(a.rules)
    for key in ("log", "events_file"):
        if getattr(a, key) is not None:
            alerts[key] = str(getattr(a, key))
    if a.email is not None:
        email = plain(a.email)
        email["from"] = email.pop("sender")  # the file's key (a Python keyword in the dataclass)
        alerts["email"] = {k: v for k, v in email.items() if v is not None}
    for key in ("slack", "alertmanager"):
        if getattr(a, key) is not None:
            alerts[key] = plain(getattr(a, key))
    out["alerts"] = alerts
    return out


def secret_status(cfg: Config) -> list[str]:
    """``KEY: VARIABLE (set | not set)`` for every ``*_env`` key of the configuration."""
    lines = []

    def walk(doc, where):
        if isinstance(doc, dict):
            for k, v in doc.items():
                if k.endswith("_env") and v:
                    lines.append(f"{where}{k}: {v} ({'set' if os.environ.get(v) else 'not set'})")
                walk(v, f"{where}{k}.")
        elif isinstance(doc, list):
            for i, v in enumerate(doc):
                walk(v, f"{where[:-1]}[{i}].")

    walk(effective(cfg), "")
    return lines
