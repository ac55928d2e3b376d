"""The service configuration, declared once: one model per section, alerts included.

Each key is a typed field with its default, its range (``ge``/``le``, in the unit its name ends in) and its
meaning (the field's description). The same model validates a file (:mod:`monitor.config.file`: reading,
one-line errors, printing, the JSON Schema), the command line's options, and writes the reference
(``docs/configuration.md``, :mod:`monitor.config.reference`). Adding a key is adding a field.

Why one module of ~750 lines: it is the one place every key of the file is declared, section by section,
with its type, default, range and meaning; split, a key's siblings and the checks between them would
live apart.

Every error names the key and the problem in one line (``ConfigError: store.publish[0].url: missing``).
Keys whose value is a secret end in ``_env`` and hold the *name* of an environment variable, never the
secret. Relative paths are relative to the file.
"""

from __future__ import annotations

import datetime as dt
import os
import re
from enum import StrEnum
from pathlib import Path
from typing import Annotated, Any
from urllib.parse import urlsplit, urlunsplit

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainSerializer,
    PrivateAttr,
    ValidationInfo,
    WithJsonSchema,
    model_validator,
)

from monitor.core.constants import (
    DEFAULT_HALF_STEPS,
    DEFAULT_STEP_URAD,
    MAX_GRID_SPREAD_RAD,
    PROCESSING_CHANGE_URAD,
    SPEC_KM,
    URAD,
)
from monitor.core.satellites import SATELLITES
from monitor.core.vocabulary import (
    DEFAULT_COST,
    DEFAULT_KERNEL,
    Cost,
    Kernel,
    PublishKind,
    ReadMode,
    SourceKind,
)

NODD_BUCKETS = {s.short: s.bucket for s in SATELLITES.values()}


class ConfigError(ValueError):
    """A configuration problem, naming the key."""


class KeyProblem(ValueError):
    """Raised by a section's own checks: the problem of *key* (relative to the section)."""

    def __init__(self, key: str, problem: str):
        super().__init__(problem)
        self.key = key


# -- value types: what a key may hold, checked where it is read


def _no_nul(text: str) -> str:
    if "\x00" in text:
        raise ValueError("contains a NUL character")
    return text


def _path(value: Any, info: ValidationInfo) -> Path:
    """A path from the file: ``~`` and ``$VARS`` expanded, relative to the file's folder."""
    if not isinstance(value, str):
        raise ValueError(f"expected a path, got {type(value).__name__} {str(value)[:60]!r}")
    _no_nul(value)
    p = Path(os.path.expandvars(value)).expanduser()
    base = (info.context or {}).get("base")
    return p if p.is_absolute() or base is None else base / p


def _url(value: str) -> str:
    """An http(s) URL without credentials in it (secrets come from *_env variables)."""
    try:
        parts = urlsplit(value)
    except ValueError:
        raise ValueError(f"{value!r} is not a URL") from None
    if parts.scheme not in ("http", "https") or not parts.netloc:
        raise ValueError(f"{redact_url(value)!r} is not an http(s) URL")
    if parts.username or parts.password or "@" in parts.netloc:
        raise ValueError(
            "credentials may not be written in a URL; name environment variables with the *_env keys"
        )
    return value.rstrip("/")


ENV_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,127}", re.ASCII)


def _env_name(value: str) -> str:
    if not ENV_NAME.fullmatch(value):
        raise ValueError("a value is not the name of an environment variable")
    return value


def _hhmm(value: Any) -> dt.time:
    if isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 24 * 60:
        # YAML 1.1 reads an unquoted 3:30 as a base-60 number
        raise ValueError(
            f"{value} is not HH:MM (YAML reads an unquoted {value // 60}:{value % 60:02d} as the number "
            f"{value}: quote it, '{value // 60:02d}:{value % 60:02d}')"
        )
    m = re.fullmatch(r"(\d{1,2}):(\d{2})", value, re.ASCII) if isinstance(value, str) else None
    if not m or int(m[1]) > 23 or int(m[2]) > 59:
        raise ValueError(f"{value!r} is not HH:MM")
    return dt.time(int(m[1]), int(m[2]))


def _address(value: str) -> str:
    if "@" not in value:
        raise ValueError(f"{value!r} is not an address")
    return value


Text = Annotated[str, AfterValidator(_no_nul)]
FilePath = Annotated[Path, BeforeValidator(_path), WithJsonSchema({"type": "string"})]
Url = Annotated[
    str, AfterValidator(_no_nul), AfterValidator(_url), WithJsonSchema({"type": "string", "format": "uri"})
]
EnvName = Annotated[
    str, AfterValidator(_env_name), WithJsonSchema({"type": "string", "pattern": ENV_NAME.pattern})
]
Address = Annotated[str, AfterValidator(_no_nul), AfterValidator(_address)]
TimeOfDay = Annotated[
    dt.time,
    BeforeValidator(_hhmm),
    PlainSerializer(lambda t: t.strftime("%H:%M"), return_type=str),
    WithJsonSchema({"type": "string", "pattern": r"^\d{1,2}:\d{2}$"}),
]


def key(default: Any, meaning: str, lo: float | None = None, hi: float | None = None, **kw: Any) -> Any:
    """A configuration key: its default (``...``: required; a section class: that section's defaults), its
    meaning, its accepted range lo..hi (inclusive, in the unit its name ends in)."""
    if isinstance(default, type):
        return Field(default_factory=default, description=meaning, **kw)
    if isinstance(default, StrEnum):
        kw.setdefault("strict", False)  # the file holds the member's string
    return Field(default, description=meaning, ge=lo, le=hi, **kw)


class Section(BaseModel):
    """A section of the file: known keys only, exact types (no '5' for 5, no true for 1), finite numbers."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, validate_assignment=False)


def parse_listen(text: str) -> tuple[str, int]:
    """``HOST:PORT`` (``[::1]:PORT`` for IPv6) as (host, port); ValueError naming the value otherwise."""
    host, sep, port = str(text).rpartition(":")
    host = host[1:-1] if host.startswith("[") and host.endswith("]") else host
    if not sep or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ValueError(f"{text!r} is not HOST:PORT")
    return host, int(port)


def check_listen(text: str) -> str:
    """``off`` or ``HOST:PORT`` (the daemon's HTTP endpoint)."""
    if text != "off":
        try:
            parse_listen(text)
        except ValueError as exc:
            raise ValueError(f"{exc} (or off)") from None
    return text


BUCKET = re.compile(r"[a-z0-9][a-z0-9.-]{1,61}[a-z0-9]", re.ASCII)


def _buckets(value: Any) -> Any:
    """The published bucket of every satellite, those given replacing theirs."""
    return {**NODD_BUCKETS, **value} if isinstance(value, dict) else value


class CalibrationDifference(Section):
    """A simulated CrIS-VIIRS calibration difference (``source.calibration.SATELLITE``): the BT CrIS reports
    is T + bias_k + gain (T - 280 K) + nonlinear_k ((T - 280 K) / 30 K)^2."""

    bias_k: float = key(0.0, "CrIS minus VIIRS BT at 280 K.", -5, 5)
    gain: float = key(
        0.0, "Relative gain difference (0.01: CrIS BT departs 1 % of T - 280 K more).", -0.1, 0.1
    )
    nonlinear_k: float = key(0.0, "Quadratic term, its value 30 K from 280 K.", -5, 5)


class SourceConfig(Section):
    """The ``source`` section: where granules come from, and the bounds of every request to NODD."""

    kind: SourceKind = key(
        ...,
        strict=False,
        meaning="Where granules come from: nodd (NOAA's archive on S3), local (a directory tree) "
        "or simulated (the offline demo).",
    )
    path: FilePath | None = key(
        None, "Root of the local tree (kind local); every *.h5 below it is considered."
    )
    endpoint: Url = key(
        "https://{bucket}.s3.amazonaws.com",
        "NODD URL template; {bucket} is replaced by the satellite's bucket.",
    )
    buckets: Annotated[dict[str, Text], BeforeValidator(_buckets)] = key(
        dict(NODD_BUCKETS), "NODD bucket per satellite (mapping); keys not given keep the published buckets."
    )
    read: ReadMode = key(
        ReadMode.RANGES,
        "How NODD granules are read: ranges (in place, only the datasets and scans the day needs, "
        "through a block cache on disk) or whole (each file downloaded whole first).",
    )
    timeout_s: float = key(
        60.0,
        "Wall-clock bound of a listing page (body included) and of the headers of any "
        "answer; also the socket timeout.",
        0.1,
        3600,
    )
    retries: int = key(5, "Retries of a failed request (backoff doubling from backoff_s).", 0, 20)
    backoff_s: float = key(1.5, "First wait between retries.", 0.01, 600)
    daily_budget_mb: float = key(
        6000.0,
        "Most bytes downloaded in one satellite-day run (whole files or ranges); what would exceed it is "
        "skipped with the reason.",
        1,
        1e6,
    )
    retention_days: int = key(
        7,
        "Downloaded files older than this are removed from the cache at the start of a "
        "run (kind simulated: this many simulated days are kept).",
        0,
        3650,
    )
    cache_max_mb: float = key(
        20000.0,
        "Before every run the least recently used files go until the cache holds at most this (downloads, "
        "and the blocks of files read in place; a run adds at most daily_budget_mb).",
        0,
        1e8,
    )
    run_deadline_min: float = key(
        180.0, "Every request of one satellite-day run ends by this time after the run started.", 1, 1440
    )
    max_list_pages: int = key(
        100, "Most pages of one listing (a day of one product is ~3 pages of 1000 keys).", 1, 10000
    )
    max_listed_keys: int = key(20000, "Most keys of one listing.", 1, 10**6)
    max_retry_after_s: float = key(
        120.0, "A server asking to wait longer than this (Retry-After) ends the attempt.", 1, 3600
    )
    min_rate_kb_s: float = key(
        50.0, "A download that brings less than this over any stall_window_s is cut (and retried).", 1, 1e6
    )
    stall_window_s: float = key(
        30.0,
        "The sliding window over which a download must keep up min_rate_kb_s; a "
        "silence this long cuts it too.",
        1,
        3600,
    )
    granules: int = key(4, "Consecutive CrIS granules simulated per satellite-day (kind simulated).", 1, 100)
    profile: Text = key(
        "paper", "Error profile injected by the simulator (paper, random, zero or a file; kind simulated)."
    )
    seed: int = key(0, "Seed of the simulator (kind simulated).", 0, 2**31 - 1)
    calibration: dict[str, CalibrationDifference] = key(
        {},
        "CrIS-VIIRS calibration difference simulated per satellite (kind simulated; mapping of the keys "
        "below); none: the instruments agree.",
        json_schema_extra={"x-key": "satellite"},
    )

    @model_validator(mode="after")
    def _consistent(self) -> SourceConfig:
        if "{bucket}" not in self.endpoint:
            raise KeyProblem("endpoint", f"{self.endpoint!r} has no {{bucket}} placeholder")
        for sat in self.calibration:
            if sat not in SATELLITES:
                raise KeyProblem(f"calibration.{sat}", f"not one of {', '.join(SATELLITES)}")
        for sat, bucket in self.buckets.items():
            if sat not in SATELLITES:
                raise KeyProblem(f"buckets.{sat}", f"not one of {', '.join(SATELLITES)}")
            if not BUCKET.fullmatch(bucket):
                raise KeyProblem(f"buckets.{sat}", f"{bucket!r} is not a bucket name")
        if self.kind == SourceKind.LOCAL:
            if self.path is None:
                raise KeyProblem("path", "missing")
            if not self.path.is_dir():
                raise KeyProblem("path", f"{self.path} is not a directory")
        return self


class ScheduleConfig(Section):
    """The ``schedule`` section: when the daemon runs and which days it (re)assesses."""

    time_utc: TimeOfDay = key(dt.time(3, 30), "Time of the daily run, HH:MM UTC.")
    catch_up_days: int = key(
        7, "Days back (ending lag_days ago) that are assessed when they have no completed run.", 1, 366
    )
    misfire_grace_hours: float = key(
        6.0, "A daily run missed by less than this (e.g. host asleep) still runs.", 0.01, 72
    )
    lag_days: int = key(
        1, "The daily run assesses the day that ended this many days ago (archive latency).", 0, 30
    )
    no_data_retry_days: int = key(
        3,
        "A day found empty is tried again for this many days after it is due, then "
        "recorded as no_data_final.",
        0,
        366,
    )
    run_budget_min: float = key(
        240.0,
        "A satellite-day run longer than this makes /healthz unhealthy and stops "
        "feeding the systemd watchdog (a restart follows). Keep it above "
        "source.run_deadline_min.",
        0.01,
        10080,
    )

    def no_data_horizon(self, today: dt.date) -> dt.date:
        """Days before this one that were found empty are not tried again (their no_data is final)."""
        return today - dt.timedelta(days=self.lag_days + self.no_data_retry_days)

    def days_to_run(self, done: set[dt.date], today: dt.date) -> list[dt.date]:
        """The days of the catch-up window (ending lag_days before *today*) not in *done*, oldest first."""
        last = today - dt.timedelta(days=self.lag_days)
        return sorted(
            d for d in (last - dt.timedelta(days=k) for k in range(self.catch_up_days)) if d not in done
        )

    def next_run(self, now: dt.datetime | None = None) -> dt.datetime:
        """The next scheduled daily run (UTC) after *now*."""
        now = now or dt.datetime.now(dt.timezone.utc)
        nxt = now.replace(hour=self.time_utc.hour, minute=self.time_utc.minute, second=0, microsecond=0)
        return nxt if nxt > now else nxt + dt.timedelta(days=1)


class SceneConfig(Section):
    """The ``scenes`` section: which CrIS granules of a day are assessed."""

    candidates: int = key(
        40, "CrIS granules of the day scored for inhomogeneity (spread over the day).", 1, 1000
    )
    keep: int = key(14, "Most inhomogeneous granules assessed (the paper uses 14).", 1, 200)
    min_inhomogeneity_k: float = key(0.5, "A granule whose VIIRS-BT spread is below this is not used.", 0, 50)

    @model_validator(mode="after")
    def _consistent(self) -> SceneConfig:
        if self.keep > self.candidates:
            raise KeyProblem("keep", f"{self.keep} is more than scenes.candidates ({self.candidates})")
        return self


class AssessmentConfig(Section):
    """The ``assessment`` section: the perturbation grid and the collocation."""

    half_steps: int = key(
        DEFAULT_HALF_STEPS,
        "Perturbations on each side of zero per direction: the grid is (2n+1)^2 (21 x 21).",
        1,
        40,
    )
    step_urad: float = key(
        DEFAULT_STEP_URAD,
        "Perturbation step (375 m at nadir from 833 km); half_steps^2 x step_urad <= 200000.",
        10,
        5000,
    )
    kernel: Kernel = key(
        DEFAULT_KERNEL,
        "CrIS footprint weighting: footprint (the FOV's radially symmetric response fitted over four annuli "
        "out to 0.64 deg, reported as its widths) or top-hat (the paper's 0.963 deg cone; biased by a real "
        "FOV's smooth response).",
    )
    cost: Cost = key(
        DEFAULT_COST,
        "The cost minimised over the perturbations: stdev (the paper's equation 8, "
        "STDEV(BT_VIIRS - BT_CrIS)) or regression (its residual after regression on BT_CrIS: a CrIS-VIIRS "
        "gain or bias does not move it).",
    )
    workers: int = key(2, "Threads of the compiled VIIRS preparation and collocation kernels.", 1, 64)
    min_coverage: float = key(
        0.97,
        "Share of a turned cone that VIIRS pixels must cover for the FOV to count (the swath's edges and "
        "gaps leave cones part empty).",
        0.5,
        1.0,
    )
    min_samples: int = key(
        30, "Fewest usable FOVs for a FOR's estimate (fewer: flagged few_samples), and for a day.", 3, 10**6
    )
    flat_contrast: float = key(
        0.03,
        "Least relative depth of a FOR's cost minimum; a shallower one is flagged flat (uniform scenes).",
        0.0,
        1.0,
    )
    max_sigma_urad: float = key(
        250.0, "Largest sigma of a trusted offset (urad, ~0.55 step); larger is flagged uncertain.", 1.0, 1e5
    )
    sigma_floor_urad: float | None = key(
        None,
        "Added in quadrature to the jackknife's sigma: the estimator's own error (urad). None: the kernel's "
        "calibrated floor (2 with footprint, 5 with top-hat).",
        0.0,
        1000.0,
    )
    uncertainty: bool = key(
        True, "Compute the jackknife's sigmas (off: offsets without sigmas, flags from the cost alone)."
    )

    @property
    def step_rad(self) -> float:
        """The perturbation step in radians."""
        return self.step_urad * URAD

    @model_validator(mode="after")
    def _consistent(self) -> AssessmentConfig:
        spread = self.half_steps**2 * self.step_urad * URAD
        if spread > MAX_GRID_SPREAD_RAD:
            raise KeyProblem(
                "half_steps",
                f"{self.half_steps} with step_urad {self.step_urad:g}: half_steps^2 x step_urad = "
                f"{spread / URAD:.0f} urad is more than {MAX_GRID_SPREAD_RAD / URAD:.0f} (the widest grid of "
                "the compiled collocation)",
            )
        return self


def _paths(value: Any) -> Any:
    """One path or a list of paths."""
    if isinstance(value, str):
        return (value,)
    if not isinstance(value, list):
        raise ValueError(f"expected a list of paths, got {value!r}")
    return tuple(value)


class FingerprintConfig(Section):
    """The ``fingerprint`` section: the LOS fingerprint of the GEO files and the EP it points to."""

    granules: int = key(
        100, "GEO granules per day sampled (spread over the day) for the LOS fingerprint.", 1, 2000
    )
    threshold_urad: float = key(
        PROCESSING_CHANGE_URAD,
        "A FOR whose fingerprint angle moves more than this is a processing change.",
        0.1,
        10000,
    )
    ep_library: Annotated[tuple[FilePath, ...], BeforeValidator(_paths)] = key(
        (), "EP files or directories to identify the EP in use from; empty: the packaged real EPs."
    )


class ExportConfig(Section):
    """The ``export`` section: who publishes the exported NetCDF (ACDD 1.3 discovery attributes); a key
    left out leaves its attribute out."""

    institution: Text | None = key(None, "ACDD institution: the organisation that runs the monitor.")
    creator_name: Text | None = key(None, "ACDD creator_name: the team or person who made the data.")
    creator_email: Text | None = key(None, "ACDD creator_email: where users write about the data.")
    creator_url: Url | None = key(None, "ACDD creator_url: the team's page.")
    license: Text | None = key(None, "ACDD license: the terms of use (e.g. an SPDX identifier, CC0-1.0).")
    naming_authority: Text | None = key(
        None, "ACDD naming_authority, reverse DNS (gov.noaa.star); a file's id is unique within it."
    )
    project: Text | None = key(None, "ACDD project: the programme the data serve (e.g. JPSS).")


class HttpConfig(Section):
    """The ``http`` section."""

    listen: Annotated[Text, AfterValidator(check_listen)] = key(
        "127.0.0.1:9782",
        "HOST:PORT of /metrics, /healthz and /report/ (loopback by default; port 0: any free "
        "port; off: no endpoint). crisgeo daemon --listen overrides it.",
    )


class PublishConfig(Section):
    """One entry of ``store.publish``: a time-series database the results are written to."""

    kind: PublishKind = key(
        ...,
        strict=False,
        meaning="influx2 (InfluxDB 2 API: token) or influx1 (InfluxDB 1 / VictoriaMetrics: user, password).",
    )
    url: Url = key(..., "Base URL of the database (no credentials in it).")
    measurement: Text = key("cris_geolocation", "Measurement name of the points.")
    bucket: Text = key("crisgeo", "Bucket (influx2).")
    org: Text = key("-", "Organisation (influx2).")
    token_env: EnvName | None = key(None, "Environment variable holding the token (influx2).")
    database: Text = key("crisgeo", "Database (influx1).")
    username_env: EnvName | None = key(None, "Environment variable holding the user name (influx1).")
    password_env: EnvName | None = key(None, "Environment variable holding the password (influx1).")
    timeout_s: float = key(30.0, "Timeout of one write.", 0.1, 600)

    def secret(self, name: str) -> str | None:
        """The value of the environment variable named by the key *name* (e.g. token_env), or None."""
        return env_secret(getattr(self, name))


class StoreConfig(Section):
    """The ``store`` section."""

    sqlite: FilePath | None = key(
        None, "The SQLite store (history, alert state, outbox). Default: state_dir/crisgeo.sqlite."
    )
    publish: list[PublishConfig] = key(
        [], "Time-series databases the results are written to (list of the mappings below)."
    )
    drain_minutes: float = key(
        10.0, "The daemon sends the time-series points waiting in the outbox this often.", 0.01, 1440
    )

    @property
    def path(self) -> Path:
        """The store's file (filled in by :class:`Config`)."""
        assert self.sqlite is not None, "store.sqlite is filled in when the configuration is loaded"
        return self.sqlite


class RuleSettings(Section):
    """The alert rules' parameters: the top-level keys of the ``alerts`` section."""

    spec_km: float = key(
        SPEC_KM,
        "Specification of the geolocation error on the ground; a reliable FOR beyond it "
        "fires the spec rule (critical when value - 2 sigma is beyond it).",
        0.01,
        100.0,
    )
    min_jump_km: float = key(
        0.25, "Smallest step (median after minus median before) that counts as a jump.", 0.001, 100.0
    )
    min_bias_jump_k: float = key(
        0.1,
        "Smallest step of the daily CrIS-VIIRS BT bias at 280 K that counts as a calibration jump (the "
        "calibration_jump rule: a VIIRS LUT or CrIS calibration change).",
        0.001,
        100.0,
    )
    jump_z: float = key(
        5.0,
        "Step size in units of its standard error that counts as a jump, on any day of the "
        "recent window (blind search).",
        1.0,
        100.0,
    )
    jump_z_at_change: float = key(
        3.5, "The same at the date of a known change (events calendar, fingerprint).", 1.0, 100.0
    )
    pre_days: int = key(21, "Days before a candidate step that form the reference.", 2, 365)
    min_pre_days: int = key(7, "Fewest assessed days before a step for the test to run.", 2, 365)
    min_post_days: int = key(2, "Fewest assessed days after a step for the test to run.", 1, 365)
    post_days: int = key(14, "Days after a candidate step compared with the reference.", 1, 365)
    blind_window_days: int = key(7, "Recent days tried as step dates without a known change.", 1, 365)
    change_window_days: int = key(30, "Known changes this recent are tried as step dates.", 1, 3650)
    attribution_days: int = key(
        10, "A jump is attributed to a known change at most this many days before it.", 0, 365
    )
    active_days: int = key(14, "A jump or processing change older than this no longer fires.", 1, 3650)
    stale_hours: float = key(36.0, "No completed run for this long fires the stale rule.", 1.0, 8760.0)
    repeat_hours: float = key(24.0, "A firing alert is notified again after this long.", 0.1, 8760.0)

    @model_validator(mode="after")
    def _consistent(self) -> RuleSettings:
        if self.min_pre_days > self.pre_days:
            raise KeyProblem(
                "min_pre_days", f"{self.min_pre_days} is more than alerts.pre_days ({self.pre_days})"
            )
        return self


class EmailSettings(Section):
    """The ``alerts.email`` section."""

    model_config = ConfigDict(populate_by_name=True, serialize_by_alias=True)

    host: Text = key(..., "SMTP server.")
    port: int = key(587, "SMTP port.", 1, 65535)
    sender: Address = key("crisgeo@localhost", "Sender address.", alias="from")
    to: Annotated[list[Address], Field(min_length=1)] = key(..., "Recipient addresses (list).")
    starttls: bool = key(True, "Use STARTTLS (certificate verified against the system store, or cafile).")
    username_env: EnvName | None = key(None, "Environment variable holding the SMTP user name.")
    password_env: EnvName | None = key(None, "Environment variable holding the SMTP password.")
    cafile: FilePath | None = key(None, "Extra CA bundle (e.g. a site CA) to verify the server with.")
    timeout_s: float = key(30.0, "Timeout of one SMTP conversation.", 0.1, 600.0)


class SlackSettings(Section):
    """The ``alerts.slack`` section."""

    webhook_env: EnvName = key(..., "Environment variable holding the incoming-webhook URL.")
    retries: int = key(3, "Retries when Slack answers 429 or 5xx.", 0, 20)
    max_wait_s: float = key(30.0, "Longest wait honoured from a Retry-After header.", 0.0, 3600.0)
    timeout_s: float = key(15.0, "Timeout of one request.", 0.1, 600.0)


class AlertmanagerSettings(Section):
    """The ``alerts.alertmanager`` section: where the service posts its alerts (Alertmanager API v2)."""

    url: Url = key(..., "Base URL of Alertmanager, e.g. http://127.0.0.1:9093.")
    timeout_s: float = key(10.0, "Timeout of one post.", 0.1, 600.0)
    validity_hours: float = key(
        3.0,
        "A firing alert is posted again at every evaluation (hourly, and after each "
        "run) with this end; if the service stops posting, Alertmanager ends it then.",
        1.5,
        168.0,
    )


class Links(BaseModel):
    """Where readers of a message find more: the top-level report_dir, report_url and dashboard_url."""

    report_dir: Path | None = None
    report_url: str | None = None
    dashboard_url: str | None = None


class AlertSettings(RuleSettings):
    """The ``alerts`` section: the rule parameters, the channels and the events calendar."""

    subject_prefix: Text = key(
        "[crisgeo]",
        "Start of every message's subject (e-mail subject, Slack headline): e.g. [crisgeo test] for a test "
        "instance, so that its messages are not taken for the operational service's.",
    )
    log: FilePath | None = key(None, "File the alert messages are appended to (a channel that cannot fail).")
    events_file: FilePath | None = key(
        None, "The events calendar (EP uploads, LUT changes) used to attribute jumps and annotate plots."
    )
    email: EmailSettings | None = key(None, "E-mail channel (mapping below); absent: none.")
    slack: SlackSettings | None = key(None, "Slack channel (mapping below); absent: none.")
    alertmanager: AlertmanagerSettings | None = key(
        None,
        "Alertmanager (mapping below): the alerts are posted to its API v2 with labels alertname, service, "
        "satellite, rule, severity and resolved there, so that Alertmanager routes, groups and silences "
        "them; absent: none.",
    )
    _links: Links = PrivateAttr(default_factory=Links)

    @model_validator(mode="after")
    def _calendar_exists(self) -> AlertSettings:
        if self.events_file is not None and not self.events_file.is_file():
            # read as empty, a missing calendar would lose jump attribution without a word
            raise KeyProblem(
                "events_file",
                f"{self.events_file} does not exist (copy configs/events.yaml there, or remove the key)",
            )
        return self

    def linked(self, links: Links) -> AlertSettings:
        """These settings, pointing their messages at *links*."""
        self._links = links
        return self

    @property
    def links(self) -> Links:
        """The report and dashboard the messages point to (the top-level keys)."""
        return self._links

    @property
    def channels(self) -> list[str]:
        """The names of the configured channels."""
        return [n for n in ("log", "email", "slack") if getattr(self, n)]


def _satellite(value: str) -> str:
    if value not in SATELLITES:
        raise ValueError(f"{value!r} is not one of {', '.join(SATELLITES)}")
    return value


class Config(Section):
    """The whole configuration, validated."""

    satellites: Annotated[list[Annotated[str, AfterValidator(_satellite)]], Field(min_length=1)] = key(
        ..., "Satellites to monitor, short names (npp, j01, j02)."
    )
    state_dir: FilePath = key(
        ...,
        "Directory of the service's state: store, download cache, simulated granules, "
        "lock. Relative paths in the file are relative to the file.",
    )
    min_free_mb: int = key(
        2000,
        "Room a satellite-day needs on state_dir's file system (downloads, block cache, simulated granules, "
        "the store); a run that finds less ends before it starts, recorded failed and redone once there is "
        "room.",
        0,
        10**7,
    )
    source: SourceConfig = key(..., "Where granules come from (the keys below).")
    schedule: ScheduleConfig = key(ScheduleConfig, "When the daemon runs (the keys below).")
    scenes: SceneConfig = key(SceneConfig, "Which granules are assessed (the keys below).")
    assessment: AssessmentConfig = key(
        AssessmentConfig, "The perturbation grid and collocation (the keys below)."
    )
    fingerprint: FingerprintConfig = key(FingerprintConfig, "The LOS fingerprint (the keys below).")
    http: HttpConfig = key(HttpConfig, "The daemon's HTTP endpoint (the key below).")
    export: ExportConfig = key(ExportConfig, "Publisher attributes of exported NetCDF (the keys below).")
    store: StoreConfig = key(StoreConfig, "Where results are kept and published (the keys below).")
    alerts: AlertSettings = key(AlertSettings, "Alert rules and channels (the keys below).")
    report_dir: FilePath | None = key(
        None,
        "Where the HTML report is regenerated after every run (and served under /report/). None: no report.",
    )
    report_url: Url | None = key(
        None,
        "The address at which readers open report_dir (e.g. behind a reverse "
        "proxy); messages link REPORT_URL/SATELLITE/. Without it they name the path on "
        "the server.",
    )
    dashboard_url: Url | None = key(None, "Link to the Grafana dashboard, added to every message.")
    _file: Path | None = PrivateAttr(default=None)

    @model_validator(mode="after")
    def _consistent(self) -> Config:
        if len(set(self.satellites)) != len(self.satellites):
            raise KeyProblem("satellites", "a satellite is listed twice")
        _check_creatable(self.state_dir, "state_dir")
        if self.store.sqlite is None:
            self.store.sqlite = self.state_dir / "crisgeo.sqlite"
        self.alerts.linked(
            Links(report_dir=self.report_dir, report_url=self.report_url, dashboard_url=self.dashboard_url)
        )
        return self

    @property
    def path(self) -> Path | None:
        """The file the configuration was loaded from."""
        return self._file

    @property
    def events_file(self) -> Path | None:
        """The events calendar (``alerts.events_file``): attribution of jumps, annotations, the report."""
        return self.alerts.events_file

    @property
    def cache_dir(self) -> Path:
        """Where downloads are cached: ``state_dir/cache``."""
        return self.state_dir / "cache"


def _check_creatable(path: Path, where: str) -> None:
    """*path* is a directory, or can be made one: its nearest existing ancestor is a writable directory
    on a file system that holds files (not /proc or /sys). Nothing is created."""
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe == path and not path.is_dir():
        raise KeyProblem(where, f"{path} exists and is not a directory")
    if not probe.is_dir() or not os.access(probe, os.W_OK | os.X_OK):
        raise KeyProblem(where, f"{path} cannot be created ({probe} is not a writable directory)")
    if probe != path and os.statvfs(probe).f_blocks == 0:  # proc, sysfs and the like: no room for files
        raise KeyProblem(where, f"{path} cannot be created ({probe} is a virtual file system)")


def env_secret(name: str | None) -> str | None:
    """The value of the environment variable *name* (a ``*_env`` key's value), or None."""
    return os.environ.get(name) if name else None


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
