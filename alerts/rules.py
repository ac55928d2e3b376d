"""Alert rules: specification breach, jumps of the offsets or of the CrIS-VIIRS bias (with the change that
preceded them), stale data, failed runs.

Each rule turns what the store holds into findings, one per satellite (and per jump). A finding is
identified by rule + satellite + group, which is what the alert state tracks.
"""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass, field

import numpy as np

from monitor.config.alert_settings import RuleSettings
from monitor.core.constants import N_FOR
from monitor.core.vocabulary import DONE, SCHEDULER_KINDS, EventKind, Rule, RunStatus, Severity
from monitor.history.changes import preceding_change
from monitor.history.records import History

UTC = dt.timezone.utc


@dataclass(frozen=True)
class Watched:
    """A daily per-FOR quantity a jump rule watches: its stored *components* (field, label), *unit*, the
    smallest step that counts (the RuleSettings key *min_step_key*) and the floor of its day-to-day scatter
    (*floor*, in *unit*: a series quieter than that is not made oversensitive)."""

    rule: Rule
    what: str
    components: tuple
    unit: str
    min_step_key: str
    floor: float

    def min_step(self, s: RuleSettings) -> float:
        return float(getattr(s, self.min_step_key))


GEOLOCATION = Watched(
    Rule.JUMP,
    "geolocation",
    (("in_track_km", "in-track"), ("cross_track_km", "cross-track")),
    "km",
    "min_jump_km",
    0.02,
)
# the CrIS-VIIRS BT bias at 280 K (monitor/estimation/intercal.py): a VIIRS LUT or a CrIS calibration change
# moves it
CALIBRATION = Watched(
    Rule.CALIBRATION_JUMP, "CrIS-VIIRS calibration", (("bias_k", "bias"),), "K", "min_bias_jump_k", 0.01
)
COMPONENTS = GEOLOCATION.components
GROUPS = {
    "FOR 1-10": range(0, 10),
    "FOR 11-20": range(10, 20),
    "FOR 21-30": range(20, N_FOR),
    "all FORs": range(N_FOR),
}


@dataclass
class Finding:
    """What a rule found: rule, satellite, severity, summary, detail lines, group."""

    rule: str
    satellite: str
    severity: str
    summary: str
    lines: list = field(default_factory=list)
    group: str = ""
    data: dict = field(default_factory=dict)

    @property
    def fingerprint(self) -> str:
        """rule:satellite:group, the identity the alert state tracks."""
        return f"{self.rule}:{self.satellite}:{self.group}"


def spec_finding(store: History, satellite: str, s: RuleSettings) -> Finding | None:
    """FORs of the latest day beyond the specification (:meth:`monitor.core.result.ForOffset.spec_breaches`:
    in-track or cross-track, each on its own; FORs flagged unreliable never alert).

    Critical when every breach of a FOR holds beyond the uncertainty (|error| - 2 sigma > spec), warning
    otherwise.
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


def _series(store: History, satellite: str, watched: Watched) -> tuple[list, dict[str, np.ndarray]]:
    series = store.series(satellite)
    reliable = series.reliable()
    return series.days, {c: np.where(reliable, series.values[c], np.nan) for c, _ in watched.components}


def step_test(
    y: np.ndarray, days: list, split: dt.date, s: RuleSettings, floor: float = GEOLOCATION.floor
) -> tuple[float, float] | None:
    """(delta, z) of a step at *split* in the daily series *y*, or None when the windows are too short.

    Robust two-sample comparison: difference of medians after/before the split, scaled by the MAD of
    the pre-split days (floored at *floor*, 20 m for the offsets) with the sampling error of a median
    (sqrt(pi/2) / sqrt(n)).
    """
    d = np.array([x.toordinal() for x in days])
    k = split.toordinal()
    pre = y[(d < k) & (d >= k - s.pre_days) & np.isfinite(y)]
    post = y[(d >= k) & (d < k + s.post_days) & np.isfinite(y)]
    if len(pre) < s.min_pre_days or len(post) < s.min_post_days:
        return None
    delta = float(np.median(post) - np.median(pre))
    scale = max(1.4826 * float(np.median(np.abs(pre - np.median(pre)))), floor)
    se = scale * math.sqrt(math.pi / 2) * math.sqrt(1 / len(pre) + 1 / len(post))
    return delta, delta / se


def detect_jumps(
    days: list, values: dict, change_days: list, s: RuleSettings, watched: Watched = GEOLOCATION
) -> list[dict]:
    """Steps in the FOR-group series of the *watched* quantity, at known change days (lower threshold) and
    blind in the recent window.

    Returns one dict per split day found: split, groups [(group, component, delta, z)], fors (per-FOR
    deltas of the components that jumped), known (whether the split is a change day).
    """
    if not days:
        return []
    last = days[-1]
    candidates = {}
    for c in change_days:
        if last - dt.timedelta(days=s.change_window_days) <= c <= last:
            candidates[c] = True
    for k in range(s.blind_window_days):
        candidates.setdefault(last - dt.timedelta(days=k), False)
    found = []
    for split, known in sorted(candidates.items()):
        threshold = s.jump_z_at_change if known else s.jump_z
        hits = []
        for comp, label in watched.components:
            for g, idx in GROUPS.items():
                sub = values[comp][:, list(idx)]
                ok = np.sum(np.isfinite(sub), axis=1) >= len(idx) / 2
                with np.errstate(all="ignore"):
                    y = np.where(ok, np.nanmean(sub, axis=1), np.nan)
                t = step_test(y, days, split, s, watched.floor)
                if t and abs(t[0]) >= watched.min_step(s) and abs(t[1]) >= threshold:
                    hits.append((g, label, t[0], t[1]))
        if hits:
            fors: dict[int, list] = {}
            for comp, label in watched.components:
                if not any(h[1] == label for h in hits):
                    continue
                for i in range(N_FOR):
                    t = step_test(values[comp][:, i], days, split, s, watched.floor)
                    if t and abs(t[0]) >= watched.min_step(s):
                        fors.setdefault(i + 1, []).append((label, t[0]))
            found.append(
                {
                    "split": split,
                    "groups": hits,
                    "fors": fors,
                    "known": known,
                    "score": max(abs(h[3]) for h in hits),
                }
            )
    # one step is seen at every split day whose windows straddle it (a sharp step, days after it too, while
    # the reference median is still the old level): one per cluster, a known change first, else the strongest
    found.sort(key=lambda j: j["split"])
    kept: list[dict] = []
    for j in found:
        if kept and (j["split"] - kept[-1]["split"]).days < s.post_days:
            if (j["known"], j["score"]) > (kept[-1]["known"], kept[-1]["score"]):
                kept[-1] = j
            continue
        kept.append(j)
    return kept


def jump_findings(
    store: History,
    satellite: str,
    changes: list,
    s: RuleSettings,
    today: dt.date,
    watched: Watched = GEOLOCATION,
) -> list[Finding]:
    """A finding per recent step in the FOR-group series of the *watched* quantity (the offsets, or the
    CrIS-VIIRS bias: :data:`CALIBRATION`), attributed to the change before it."""
    days, values = _series(store, satellite, watched)
    jumps = detect_jumps(days, values, sorted({c.time.date() for c in changes}), s, watched)
    u = watched.unit
    out = []
    for j in jumps:
        if (today - j["split"]).days > s.active_days:
            continue
        change = preceding_change(changes, j["split"], s.attribution_days)
        cause = (
            f"preceded by {change.label()}"
            if change
            else f"no known change in the {s.attribution_days} days before it"
        )
        who = (
            {"cris": "CrIS", "viirs": "VIIRS", "common": "CrIS/VIIRS common"}[change.instrument]
            if change
            else "unknown"
        )
        groups = "; ".join(f"{g} {label} {d:+.2f} {u} (z {z:+.1f})" for g, label, d, z in j["groups"])
        lines = [f"step from {j['split']}: {groups}", f"attribution: {cause}"]
        lines += [
            f"FOR {k:2d}: " + ", ".join(f"{label} {d:+.2f} {u}" for label, d in v)
            for k, v in sorted(j["fors"].items())
        ]
        out.append(
            Finding(
                watched.rule,
                satellite,
                Severity.WARNING,
                f"{satellite}: {watched.what} jump from {j['split']} ({who} change before it)"
                if change
                else f"{satellite}: {watched.what} jump from {j['split']} with no known change before it",
                lines,
                group=j["split"].isoformat(),
                data={
                    "split": j["split"].isoformat(),
                    "instrument": change.instrument if change else None,
                    "fors": sorted(j["fors"]),
                    "change": change.label() if change else None,
                },
            )
        )
    return out


def stale_finding(store: History, satellite: str, s: RuleSettings, now: dt.datetime) -> Finding | None:
    """No successful assessment for longer than the limit (counted from the first run if none succeeded)."""
    runs = store.runs(satellite)
    if not runs:
        return None
    ok = [r for r in runs if r.status == RunStatus.OK]
    since = dt.datetime.fromisoformat((ok[-1].finished or ok[-1].started) if ok else runs[0].started)
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
    """The latest run failed, or the scheduler reported a failed or missed job since the last good run."""
    runs = store.runs(satellite)
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
    """CrIS geolocation processing changes found by the LOS fingerprint in the last ``active_days``."""
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
