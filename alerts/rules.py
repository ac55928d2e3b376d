"""Alert rules: specification breach, steps of the offsets or of the CrIS-VIIRS bias (tested with their
sigmas, :mod:`alerts.steps`, named after the known change they follow), stale data, failed runs.

Each rule turns what the store holds into findings, one per satellite (and per jump). A finding is
identified by rule + satellite + group (its ``alert_id``), which is what the alert state tracks.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from alerts.noise import MIN_HISTORY_DAYS, FittedNoise, fitted_before
from alerts.steps import StepRules, detect, replay_reach
from monitor.config.alert_settings import RuleSettings
from monitor.core.constants import N_FOR
from monitor.core.vocabulary import DONE, SCHEDULER_KINDS, EventKind, Rule, RunStatus, Severity
from monitor.history.changes import Change
from monitor.history.records import AlertStore, History, last_success

UTC = dt.timezone.utc
CHANGED = {"cris": "CrIS", "viirs": "VIIRS", "common": "CrIS/VIIRS common"}


@dataclass(frozen=True)
class Watched:
    """A daily per-FOR quantity a jump rule watches: its stored fields per direction with their sigmas'
    fields, the directions' labels, its unit, and its practical size (the RuleSettings key, in *unit*)."""

    rule: Rule
    what: str
    fields: tuple[str, ...]
    sigmas: tuple[str, ...]
    labels: tuple[str, ...]
    unit: str
    practical_key: str
    digits: int  # decimals its sizes are shown with
    band: str = ""  # the VIIRS band of a quantity measured per band

    @property
    def key(self) -> str:  # numpydoc ignore=RT01
        """The quantity's name where several share a rule (its noise fits, its alerts' groups):
        ``calibration_jump:M15``; the rule alone where it watches one quantity."""
        return f"{self.rule}:{self.band}" if self.band else str(self.rule)

    def rules(self, s: RuleSettings) -> StepRules:
        """The step detector's parameters for this quantity under the settings *s*.

        Parameters
        ----------
        s : RuleSettings
            The rules' parameters.

        Returns
        -------
        StepRules
            The parameters.
        """
        return StepRules(
            rate_per_year=s.false_detections_per_year,
            rate_at_change=s.false_detection_at_change,
            baseline_days=s.pre_days,
            min_baseline_days=s.min_pre_days,
            discovery_days=s.discovery_days,
            size_days=s.post_days,
            practical=float(getattr(s, self.practical_key)),
            attribution_days=s.attribution_days,
        )


GEOLOCATION = Watched(
    Rule.JUMP,
    "geolocation",
    ("d_alpha_urad", "d_beta_urad"),
    ("sigma_alpha_urad", "sigma_beta_urad"),
    ("in-track", "cross-track"),
    "urad",
    "practical_step_urad",
    0,
)
# the CrIS-VIIRS BT bias at 280 K (monitor/estimation/intercal.py): a VIIRS LUT or a CrIS calibration change
# moves it
CALIBRATION = Watched(
    Rule.CALIBRATION_JUMP,
    "CrIS-VIIRS calibration",
    ("bias_k",),
    ("sigma_bias_k",),
    ("bias",),
    "K",
    "min_bias_jump_k",
    3,
)


@dataclass
class Finding:
    """What a rule found: rule, satellite, severity, summary, detail lines, group, and what the rule measured
    (*data*: a step's size, its attribution, for the report and the Alertmanager labels)."""

    rule: str
    satellite: str
    severity: Severity
    summary: str
    lines: list[str] = field(default_factory=list)
    group: str = ""
    data: dict[str, Any] = field(default_factory=dict)

    @property
    def alert_id(self) -> str:  # numpydoc ignore=RT01
        """rule:satellite, and :group where there is one: the alert's identity, tracked by the alert state."""
        return ":".join(p for p in (self.rule, self.satellite, self.group) if p)


def spec_finding(store: History, satellite: str, s: RuleSettings) -> Finding | None:
    """FORs of the latest day beyond the specification (:meth:`monitor.core.result.ForOffset.spec_breaches`:
    in-track or cross-track, each on its own; FORs flagged unreliable never alert).

    Critical when every breach of a FOR holds beyond the uncertainty (|error| - 2 sigma > spec), warning
    otherwise.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    s : RuleSettings
        The rules' parameters.

    Returns
    -------
    Finding or None
        None within the specification.
    """
    day = store.latest_day(satellite)
    if day is None:
        return None
    rows = [(f, f.spec_breaches(s.spec_km)) for f in store.day_result(satellite, day)]
    rows = [(f, b) for f, b in rows if b]
    if not rows:
        return None
    critical = [all(x.beyond_doubt for x in b) for _, b in rows]
    severity = Severity.CRITICAL if any(critical) else Severity.WARNING
    fors = [f.for_index for f, _ in rows]
    lines = [
        f"FOR {f.for_index:2d}: in-track {f.in_track_km:+.2f} +- {f.sigma_in_track_km:.2f} km, cross-track "
        f"{f.cross_track_km:+.2f} +- {f.sigma_cross_track_km:.2f} km, total {f.total_km:.2f} km "
        f"(spec {s.spec_km} km each way){'' if c else ' (within 2 sigma of the spec)'}"
        for (f, _), c in zip(rows, critical, strict=True)
    ]
    return Finding(
        Rule.SPEC,
        satellite,
        severity,
        f"{satellite}: {len(rows)} FOR(s) beyond the {s.spec_km} km specification on {day}: "
        f"FOR {', '.join(map(str, fors))}",
        lines,
        data={"day": day.isoformat(), "fors": fors},
    )


def watched_series(
    store: History,
    satellite: str,
    watched: Watched,
    since: dt.date | None = None,
    until: dt.date | None = None,
) -> tuple[list, np.ndarray, np.ndarray]:
    """The days, values and sigmas (days, N_FOR, directions) of the *watched* quantity from *since* to
    *until*, NaN where a FOR is not stored or flagged unreliable.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    watched : Watched
        The quantity.
    since, until : datetime.date, optional
        The period, inclusive; None: open.

    Returns
    -------
    days : list of datetime.date
        The assessed days.
    values, sigmas : numpy.ndarray
        Shape (days, N_FOR, directions).
    """
    series = store.series(satellite, since, until, fields=watched.fields + watched.sigmas)
    reliable = series.reliable()[..., None]
    shape = (len(series), N_FOR, len(watched.fields))
    if not len(series):
        return [], np.full(shape, np.nan), np.full(shape, np.nan)
    y = np.stack([series.values[f] for f in watched.fields], axis=-1)
    sig = np.stack([series.values[f] for f in watched.sigmas], axis=-1)
    return series.days, np.where(reliable, y, np.nan), np.where(reliable, sig, np.nan)


# the noise fit's method (alerts/noise.py, alerts/steps.py): a fit kept by another method is fitted anew
FIT_METHOD = 1


@dataclass
class KeptFits:
    """The noise of the *watched* quantity on every day before a date, as the store keeps it per refit
    date (:func:`alerts.steps.detect`'s *fits*): fitted from the store's days once, then read back, so a
    daily evaluation reads its replay window, not the whole history. The fits not kept are fitted from one
    read of the history, however many are missing."""

    store: AlertStore
    satellite: str
    watched: Watched
    _history: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # (ordinals, values, sigmas)

    def __call__(self, before: int) -> FittedNoise:
        """The fit of every day before the ordinal *before*.

        Parameters
        ----------
        before : int
            The first day's ordinal not fitted.

        Returns
        -------
        FittedNoise
            The fit.
        """
        day = dt.date.fromordinal(before)
        kept = self.store.noise_fit(self.satellite, self.watched.key, day)
        if kept is not None and kept.get("method") == FIT_METHOD:
            return FittedNoise.from_dict(kept)
        if self._history is None:
            days, y, sig = watched_series(self.store, self.satellite, self.watched)
            self._history = (np.array([d.toordinal() for d in days], int), y, sig)
        fitted = fitted_before(*self._history, before)
        self.store.keep_noise_fit(
            self.satellite, self.watched.key, day, {**fitted.to_dict(), "method": FIT_METHOD}
        )
        return fitted


def jump_findings(
    store: AlertStore,
    satellite: str,
    changes: list[Change],
    s: RuleSettings,
    watched: Watched = GEOLOCATION,
) -> list[Finding]:
    """A finding per step of the *watched* quantity (the LOS offsets, or the CrIS-VIIRS bias:
    :data:`CALIBRATION`) whose split lies in the baseline's length before the latest day
    (:func:`alerts.steps.detect`), named after the known change it follows; a warning when it reaches the
    practical size, else recorded (severity info).

    Parameters
    ----------
    store : AlertStore
        The store's records (the noise fits are kept in it).
    satellite : str
        The satellite's short name.
    changes : list of Change
        Known changes.
    s : RuleSettings
        The rules' parameters.
    watched : Watched, optional
        The quantity; the LOS offsets by default.

    Returns
    -------
    list of Finding
        One per step.
    """
    latest = store.latest_day(satellite)
    if latest is None:
        return []
    rules = watched.rules(s)
    days, y, sig = watched_series(store, satellite, watched, since=latest - dt.timedelta(replay_reach(rules)))
    if len(days) < MIN_HISTORY_DAYS:  # a young or sparse history: all of it, as detect then needs
        days, y, sig = watched_series(store, satellite, watched)
    if not np.isfinite(y).any():  # nothing measured (e.g. no intercalibration)
        return []
    found = detect(days, y, sig, [c.time.date() for c in changes], rules, KeptFits(store, satellite, watched))
    u, practical, n = watched.unit, watched.rules(s).practical, watched.digits
    out = []
    for step in found:
        change = changes[step.change] if step.change is not None else None
        cause = (
            f"at {change.label()}" if change else f"no known change within {s.attribution_days} day(s) of it"
        )
        label = watched.labels[step.direction]
        head = (
            f"{satellite}: {watched.what} step from {step.split}, {label} {step.pooled:+.{n}f} +- "
            f"{step.pooled_sigma:.{n}f} {u} over {step.group}"
        )
        lines = [
            f"step from {step.split}, found on {step.seen}: {step.group} {label} {step.pooled:+.{n}f} +- "
            f"{step.pooled_sigma:.{n}f} {u} (z {step.z:.1f})"
            + ("" if step.paged else f"; below the practical size {practical:g} {u}: recorded"),
            f"attribution: {cause}",
        ]
        lines += [
            f"FOR {k + 1:2d}: "
            + ", ".join(
                f"{watched.labels[c]} {step.size[k, c]:+.{n}f} +- {step.sigma[k, c]:.{n}f} {u}"
                for c in range(len(watched.fields))
            )
            for k in range(step.size.shape[0])
            if np.isfinite(step.size[k]).any()
        ]
        out.append(
            Finding(
                watched.rule,
                satellite,
                Severity.WARNING if step.paged else Severity.INFO,
                head + (f" ({CHANGED[change.instrument]} {change.kind})" if change else " (no known change)"),
                lines,
                group=f"{watched.band}:{step.split}" if watched.band else step.split.isoformat(),
                data={
                    "band": watched.band or None,
                    "split": step.split.isoformat(),
                    "seen": step.seen.isoformat(),
                    "instrument": change.instrument if change else None,
                    "change": change.label() if change else None,
                    "group": step.group,
                    "direction": label,
                    "z": step.z,
                    "size": step.pooled,
                    "sigma": step.pooled_sigma,
                    "unit": u,
                    "paged": step.paged,
                    "fors": {
                        watched.labels[c]: {
                            "size": [None if not np.isfinite(v) else float(v) for v in step.size[:, c]],
                            "sigma": [None if not np.isfinite(v) else float(v) for v in step.sigma[:, c]],
                        }
                        for c in range(len(watched.fields))
                    },
                },
            )
        )
    return out


def stale_finding(store: History, satellite: str, s: RuleSettings, now: dt.datetime) -> Finding | None:
    """No successful assessment for longer than the limit (counted from the first run if none succeeded).

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    s : RuleSettings
        The rules' parameters.
    now : datetime.datetime
        Now, UTC.

    Returns
    -------
    Finding or None
        None when fresh.
    """
    runs = store.runs_since_success(satellite)
    since = last_success(runs)
    if since is None:
        return None
    ok = [r for r in runs if r.status == RunStatus.OK]
    age = (now - since).total_seconds() / 3600
    if age <= s.stale_hours:
        return None
    what = (
        f"last successful assessment {ok[-1].day} finished {ok[-1].finished}"
        if ok
        else "no successful assessment yet"
    )
    return Finding(
        Rule.STALE,
        satellite,
        Severity.CRITICAL,
        f"{satellite}: no successful assessment for {age:.0f} h",
        [what, f"latest run: {runs[-1].day} {runs[-1].status} {runs[-1].reason or ''}".strip()],
    )


def failure_finding(store: History, satellite: str) -> Finding | None:
    """The latest run failed, or the scheduler reported a failed or missed job since the last good run.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.

    Returns
    -------
    Finding or None
        None when the latest run is good.
    """
    runs = store.runs_since_success(satellite)  # a failure since the last good run is among them
    last_ok = max((r.id for r in runs if r.status in DONE), default=0)
    failed = [r for r in runs if r.id > last_ok and r.status == RunStatus.FAILED]
    last_ok_time = next((r.finished for r in runs if r.id == last_ok), "")
    jobs = [
        e
        for e in store.events()
        if e.kind in SCHEDULER_KINDS and e.satellite == satellite and e.time > (last_ok_time or "")
    ]
    if not failed and not jobs:
        return None
    lines = [f"run {r.day}: {r.reason}" for r in failed] + [
        f"scheduler: {e.detail.get('job')}: {e.detail.get('error', e.detail.get('text'))} "
        f"(scheduled {e.detail.get('scheduled', '?')})"
        for e in jobs
    ]
    return Finding(
        Rule.FAILURE,
        satellite,
        Severity.CRITICAL,
        f"{satellite}: {len(lines)} failed or missed run(s)",
        lines,
    )


def processing_change_findings(
    store: History, satellite: str, s: RuleSettings, today: dt.date
) -> list[Finding]:
    """CrIS geolocation processing changes found by the LOS fingerprint in the last ``active_days``.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    s : RuleSettings
        The rules' parameters.
    today : datetime.date
        Today, UTC.

    Returns
    -------
    list of Finding
        One per change.
    """
    out = []
    for e in store.events(EventKind.CHANGE_CRIS):
        if e.satellite != satellite:
            continue
        d = e.detail
        if d.get("origin") != "fingerprint":
            continue
        when = dt.datetime.fromisoformat(d["time"])
        if (today - when.date()).days > s.active_days:
            continue
        out.append(
            Finding(
                Rule.PROCESSING,
                satellite,
                Severity.WARNING,
                f"{satellite}: {d['description']}",
                [f"seen in the GEO files from {when:%Y-%m-%d %H:%M:%S} UTC, before any VIIRS comparison"],
                group=when.date().isoformat(),
                data=d,
            )
        )
    return out
