"""The jump rule on synthetic histories, through the daemon's own rule path: false detections per
satellite-year, detection within 3 days, attribution, and the reported sizes against the truth.

    python -m benchmarks.step_detection fdr --years 300 [--workers 2] [--rows FILE]
    python -m benchmarks.step_detection detect --trials 40 [--workers 2] [--rows FILE]
    python -m benchmarks.step_detection store --years 2

Each history has 365 days of 30 FORs x 2 directions: a constant profile (the paper's, scaled to a third),
the reported sigma (5, 30, 60 or 120 urad) and an error that is white at it, 1.3 times it, or shared half
by the FORs of a day with consecutive days correlated by 0.3. After each day the rules are evaluated as
the daemon evaluates them (:func:`alerts.engine.findings_for` on a :class:`History`); ``store`` runs the
same days through a SQLite store (``save_day``) and :func:`alerts.engine.evaluate` and checks that the
two give the same findings. A step is added on day 200 to every FOR or to 3 adjacent ones, in one
direction; with a known change (an EP upload at 12:00 UTC, so day 200 holds half the step) or without.

* ``fdr``: detection episodes (a finding's split date, recorded or paged) per satellite-year with no step,
  over the daily evaluations from day 45 on (the splits they decide).
* ``detect``: per case, the share of trials found (recorded or paged) within 3 days (by the evaluation after
  day 200, 201 or 202), paged within 3 days, whose first message names the injected change (or says no
  known change when there is none, or when the only change is 4 days before the step), dated within a
  day, and the rms of (size - truth) / sigma of the per-FOR sizes reported on day 202.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import numpy as np

from alerts.engine import evaluate, findings_for
from benchmarks.provenance import commit, emit
from monitor.config.alert_settings import AlertSettings
from monitor.core.bands import BANDS
from monitor.core.constants import N_FOR
from monitor.core.result import AssessmentResult, ForOffset
from monitor.core.vocabulary import Rule
from monitor.estimation.intercal import NO_FIT
from monitor.estimation.offsets import Ground, Pair, Widths, for_offset
from monitor.history.records import AlertStore, ForSeries
from monitor.service.store.sqlite import Store
from monitor.simulate.history import BAND_LEVEL_K, BAND_SIGMA_K
from monitor.simulate.profiles import paper_profile

START = dt.date(2025, 1, 1)
DAYS = 365
STEP_DAY = 200
UTC = dt.timezone.utc
NOISES = {"white": (1.0, 0.0, 0.0), "scale1.3": (1.3, 0.0, 0.0), "correlated": (1.0, 0.5, 0.3)}
ONE_DAY = dt.timedelta(days=1)
# a band's per-FOR CrIS minus VIIRS sigma on a simulated day (3-6 granules: 0.002-0.004 K, every band),
# rounded up (studies/radiometry-per-band.md)
DAY_BAND_SIGMA_K = 0.005
FIRST_EVALUATION = 45  # days of history before the rules are first evaluated


@dataclass(frozen=True)
class Case:
    """A synthetic history: the reported *sigma* (urad), the noise (a key of NOISES), a step of *size*
    (urad) on *fors* ("all" or "3") in *direction* (0 in-track, 1 cross-track), and a known change on the
    step's day (*change* "at"), 4 days before it ("before") or none."""

    sigma: float
    noise: str
    size: float = 0.0
    fors: str = "all"
    direction: int = 0
    change: str = "none"
    quantity: str = (
        "los"  # or "bias": the CrIS-VIIRS bias; or a band: its CrIS minus VIIRS (sigma, size in K)
    )
    los_step_urad: float = 0.0  # for the bias: the LOS's own step on the same day (all FORs, in-track)


def history(case: Case, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """(values, sigmas) (DAYS, N_FOR, 2) urad of *case* (its bias's: (DAYS, N_FOR, 1) K), and the FORs
    (0-based) its step moved."""
    scale, shared, lag1 = NOISES[case.noise]
    alpha, beta = paper_profile()
    level = np.stack([alpha, beta], axis=-1) / 3.0 if case.quantity == "los" else np.full((N_FOR, 1), -0.155)
    if case.quantity in BANDS:
        level = np.full((N_FOR, 1), BAND_LEVEL_K[case.quantity])
    g = rng.standard_normal((DAYS, 1, level.shape[-1]))
    h = rng.standard_normal((DAYS, N_FOR, level.shape[-1]))
    e = np.sqrt(shared) * g + np.sqrt(1.0 - shared) * h
    for t in range(1, DAYS):  # AR(1), unit variance
        e[t] = lag1 * e[t - 1] + np.sqrt(1.0 - lag1**2) * e[t]
    y = level + scale * case.sigma * e
    moved: list[int] = []
    if case.size:
        first = int(rng.integers(0, N_FOR - 2))
        moved = list(range(N_FOR)) if case.fors == "all" else [first, first + 1, first + 2]
        y[STEP_DAY:, moved, case.direction] += case.size
        if case.change == "at":  # the upload at noon: the day holds half of each level
            y[STEP_DAY, moved, case.direction] -= case.size / 2
    return y, np.full_like(y, case.sigma), moved


class MemoryHistory:
    """The :class:`monitor.history.records.History` the rules read, over arrays, as of day *today* (an
    index): the store's series, latest day and noise fits; no runs, events or granules (the rules that read
    those find nothing)."""

    def __init__(
        self,
        y: np.ndarray,
        s: np.ndarray,
        bias: tuple[np.ndarray, np.ndarray] | None = None,
        band: tuple[str, np.ndarray, np.ndarray] | None = None,
    ) -> None:
        self.y, self.s, self.today = y, s, 0
        self.bias = bias  # (bias, sigma) (DAYS, N_FOR) K, or none
        self.band = band  # (band, its CrIS minus VIIRS, sigma) (DAYS, N_FOR) K, or none
        self.days = [START + dt.timedelta(days=i) for i in range(len(y))]
        self.fits: dict[tuple[str, str, dt.date], dict] = {}  # the noise fits the store would keep

    def latest_day(self, satellite: str) -> dt.date:
        return self.days[self.today]

    def day_result(self, satellite: str, day: dt.date) -> list[ForOffset]:
        return []

    def series(
        self,
        satellite: str,
        since: dt.date | None = None,
        until: dt.date | None = None,
        fields: object = None,
    ) -> ForSeries:
        n = self.today + 1
        a = 0 if since is None else max(0, (since - START).days)
        if until is not None:
            n = min(n, (until - START).days + 1)
        nan = np.full((max(n - a, 0), N_FOR), np.nan)
        values = {
            "d_alpha_urad": self.y[a:n, :, 0],
            "d_beta_urad": self.y[a:n, :, 1],
            "sigma_alpha_urad": self.s[a:n, :, 0],
            "sigma_beta_urad": self.s[a:n, :, 1],
            "bias_k": nan if self.bias is None else self.bias[0][a:n],
            "sigma_bias_k": nan if self.bias is None else self.bias[1][a:n],
        }
        for b in BANDS:
            values[f"cris_minus_viirs_k_{b}"] = values[f"sigma_cris_minus_viirs_k_{b}"] = nan
        if self.band is not None:
            band, diff, sigma = self.band
            values[f"cris_minus_viirs_k_{band}"] = diff[a:n]
            values[f"sigma_cris_minus_viirs_k_{band}"] = sigma[a:n]
        return ForSeries(self.days[a:n], values, np.empty(0), np.ones((max(n - a, 0), N_FOR), bool))

    def noise_fit(self, satellite: str, quantity: str, before: dt.date) -> dict | None:
        return self.fits.get((satellite, quantity, before))

    def keep_noise_fit(self, satellite: str, quantity: str, before: dt.date, body: dict) -> None:
        self.fits[(satellite, quantity, before)] = body  # the days never change: a fit stays valid

    def runs(self, satellite: str | None = None) -> list:
        return []

    def runs_since_success(self, satellite: str) -> list:
        return []

    def events(self, kind: object = None) -> list:
        return []

    def granules(self, satellite: str, day: object = None, since: object = None) -> list:
        return []


def settings(folder: Path, case: Case) -> AlertSettings:
    """The default alert settings, the events calendar holding the case's known change."""
    calendar = folder / "events.yaml"
    day = START + dt.timedelta(days=STEP_DAY - (4 if case.change == "before" else 0))
    events = [] if case.change == "none" else [
        {"satellite": "j01", "time": f"{day.isoformat()}T12:00:00Z", "instrument": "cris",
         "kind": "ep_upload", "description": "EP v116 uploaded"}
    ]  # fmt: skip
    calendar.write_text(json.dumps({"events": events}))
    return AlertSettings.model_validate({"events_file": str(calendar)}, context={"base": folder})


def findings_by_day(case: Case, seed: int, first: int, last: int) -> tuple[list[tuple[int, list]], list]:
    """The findings of the case's rule (jump; calibration_jump for the bias) of each evaluation from day
    *first* to *last* (indices), and the FORs moved."""
    rng = np.random.default_rng(seed)
    y, s, moved = history(case, rng)
    rule = Rule.JUMP
    if case.quantity == "bias":  # beside it the LOS, stepping on its own
        ly, ls, _ = history(Case(120.0, "white", case.los_step_urad), rng)
        store = MemoryHistory(ly, ls, (y[..., 0], s[..., 0]))
        rule = Rule.CALIBRATION_JUMP
    elif case.quantity in BANDS:  # one band's CrIS minus VIIRS, beside the LOS stepping on its own
        ly, ls, _ = history(Case(120.0, "white", case.los_step_urad), rng)
        store = MemoryHistory(ly, ls, band=(case.quantity, y[..., 0], s[..., 0]))
        rule = Rule.CALIBRATION_JUMP
    else:
        store = MemoryHistory(y, s)
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        cfg = settings(Path(tmp), case)
        now = dt.datetime.combine(START, dt.time(6), UTC)
        for t in range(first, last + 1):
            store.today = t
            # the rules read only what MemoryHistory has (series, latest day, runs, events, granules)
            found = findings_for(cast(AlertStore, store), "j01", cfg, now + dt.timedelta(days=t + 1))
            out.append((t, [f for f in found if f.rule == rule]))
    return out, moved


def fdr_year(job: tuple[Case, int]) -> dict:
    """Detection episodes (distinct split dates) of one noise-year, and the findings' first days."""
    case, seed = job
    days, _ = findings_by_day(case, seed, FIRST_EVALUATION, DAYS - 1)
    first_seen: dict[str, tuple[int, str]] = {}
    start = START + dt.timedelta(days=FIRST_EVALUATION)
    for t, found in days:
        for f in found:  # the first evaluation replays the weeks before it at once: not a daily one
            if dt.date.fromisoformat(f.data["split"]) >= start:
                first_seen.setdefault(f.group, (t, f.severity))
    return {"episodes": len(first_seen), "paged": sum(v[1] == "warning" for v in first_seen.values()),
            "years": (DAYS - FIRST_EVALUATION) / 365.0}  # fmt: skip


def detect_trial(job: tuple[Case, int]) -> dict:
    """One step trial: when it was first found, whether paged, what its first finding named, and the
    normalised errors of its per-FOR sizes at the last evaluation."""
    case, seed = job
    days, moved = findings_by_day(case, seed, STEP_DAY - 4, STEP_DAY + 2)
    split = START + dt.timedelta(days=STEP_DAY)
    first = paged = None
    for t, found in days:
        near = [f for f in found if abs((dt.date.fromisoformat(f.data["split"]) - split).days) <= 1]
        if near and first is None:
            first = (t, near[0])
        loud = [f for f in near if f.severity == "warning"]
        if loud and paged is None:
            paged = (t, loud[0])
    if first is None:
        return {"found": False}
    last = [f for f in days[-1][1] if f.group == first[1].group]
    errors: list[float] = []
    if last:
        label = case.quantity if case.quantity != "los" else ("in-track", "cross-track")[case.direction]
        fors = last[0].data["fors"][label]
        truth = np.zeros(N_FOR)
        truth[moved] = case.size
        for k in range(N_FOR):
            size, sigma = fors["size"][k], fors["sigma"][k]
            if size is not None and sigma:
                errors.append((size - truth[k]) / sigma)
    f = (paged or first)[1]  # what the first message says (a recorded step sends none)
    return {
        "found": True,
        "delay_days": first[0] - STEP_DAY,
        "date_error_days": (dt.date.fromisoformat(f.data["split"]) - split).days,
        "paged": paged is not None and paged[0] - STEP_DAY <= 2,
        "names_change": f.data["change"] is not None,
        "errors": errors,
    }


def store_check(years: int) -> int:
    """The same white-noise histories with a known change and a step, evaluated through a SQLite store
    and alerts.engine.evaluate: the alerts recorded must be the findings of the memory path."""
    bad = 0
    for seed in range(years):
        case = Case(120.0, "white", 300.0, "3", 1, "at")
        days, _ = findings_by_day(case, seed, FIRST_EVALUATION, DAYS - 1)
        expected = {(f.group, f.severity) for _, found in days for f in found}
        y, s, _ = history(case, np.random.default_rng(seed))
        with tempfile.TemporaryDirectory() as tmp:
            cfg = settings(Path(tmp), case)
            store = Store(Path(tmp) / "s.sqlite")
            for t in range(DAYS):
                day = START + dt.timedelta(days=t)
                fors = [
                    for_offset(
                        k + 1,
                        100,
                        Pair(y[t, k, 0], y[t, k, 1], s[t, k, 0], s[t, k, 1]),
                        Ground(),
                        0.1,
                        0.2,
                        NO_FIT,
                        Widths(),
                        Pair(),
                        np.nan,
                        np.nan,
                        (),
                    )  # fmt: skip
                    for k in range(N_FOR)
                ]
                result = AssessmentResult("j01", "", "", fors, [])
                store.save_day(store.begin_run("j01", day), "j01", day, result)
                if t >= FIRST_EVALUATION:
                    evaluate(store, cfg, ["j01"], dt.datetime.combine(day, dt.time(6), UTC) + ONE_DAY)
            got = {(a.grp, a.severity) for a in store.alert_state().all() if a.rule == Rule.JUMP}
        print(f"seed {seed}: memory {sorted(expected)}, store {sorted(got)}", flush=True)
        bad += got != expected
    return bad


FDR_CASES = [Case(5.0, "white"), Case(120.0, "white"), Case(120.0, "scale1.3"), Case(120.0, "correlated"),
             Case(0.007, "correlated", quantity="bias", los_step_urad=300.0),
             *(Case(DAY_BAND_SIGMA_K, "correlated", quantity=b, los_step_urad=300.0) for b in BANDS),
             *(Case(BAND_SIGMA_K[b], "correlated", quantity=b, los_step_urad=300.0)
               for b in BANDS)]  # fmt: skip


def detect_cases() -> list[Case]:
    """The detection cases: every kind of step the rule must find."""
    out = []
    for d in (0, 1):
        out.append(Case(120.0, "white", 100.0, "all", d))
        out.append(Case(120.0, "white", 300.0, "3", d))
        out.append(Case(5.0, "white", 10.0, "all", d))
        out.append(Case(5.0, "white", 60.0, "all", d))
        out.append(Case(120.0, "correlated", 300.0, "3", d))
        out.append(Case(120.0, "correlated", 500.0, "all", d))
    out += [Case(120.0, "white", 100.0, "all", 0, "at"), Case(120.0, "white", 300.0, "3", 1, "at"),
            Case(5.0, "white", 10.0, "all", 0, "at"), Case(5.0, "white", 60.0, "all", 1, "at"),
            Case(120.0, "correlated", 500.0, "all", 0, "at"), Case(120.0, "correlated", 300.0, "3", 1, "at"),
            Case(120.0, "white", 300.0, "3", 0, "before"),
            Case(120.0, "white", 100.0, "all", 1, "before")]  # fmt: skip
    # the bias: per-FOR sigma 0.007 K (the real split halves), scenes moving every FOR's bias together
    out += [Case(0.007, "correlated", 0.1, "all", 0, "none", "bias"),
            Case(0.007, "correlated", 0.1, "all", 0, "at", "bias"),
            Case(0.007, "correlated", 0.0, "all", 0, "at", "bias", 300.0)]  # fmt: skip
    # each band's CrIS minus VIIRS, a 0.1 K step in it: at the per-FOR sigma a simulated day states
    # (DAY_BAND_SIGMA_K), and at the larger ones of the simulated history (BAND_SIGMA_K)
    out += [Case(DAY_BAND_SIGMA_K, "correlated", 0.1, "all", 0, "none", b) for b in BANDS]
    out += [Case(BAND_SIGMA_K[b], "correlated", 0.1, "all", 0, "none", b) for b in BANDS]
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", choices=("fdr", "detect", "store"))
    ap.add_argument("--years", type=int, default=300, help="noise-years per noise (fdr), histories (store)")
    ap.add_argument("--trials", type=int, default=40, help="trials per detection case")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--rows", help="append the JSON lines here")
    ap.add_argument(
        "--only",
        action="append",
        metavar="QUANTITY:NOISE:SIGMA",
        help="fdr and detect: only these cases (e.g. los:scale1.3:120, M15:correlated:0.015)",
    )
    args = ap.parse_args(argv)
    if args.mode == "store":
        bad = store_check(args.years)
        print(f"{bad} of {args.years} histories differ between the memory and the store paths")
        return 1 if bad else 0
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        if args.mode == "fdr":
            for case in FDR_CASES:
                if args.only and f"{case.quantity}:{case.noise}:{case.sigma:g}" not in args.only:
                    continue
                seeds = [(case, 1000 * (2 + FDR_CASES.index(case)) + i) for i in range(args.years)]
                years = list(pool.map(fdr_year, seeds, chunksize=4))
                n = sum(y["years"] for y in years)
                row = {"commit": commit(), "mode": "fdr", "quantity": case.quantity, "noise": case.noise,
                       "sigma": case.sigma,
                       "noise_years": round(n, 1), "per_year": sum(y["episodes"] for y in years) / n,
                       "paged_per_year": sum(y["paged"] for y in years) / n,
                       "seconds": round(time.perf_counter() - t0)}  # fmt: skip
                emit(row, args.rows)
        else:
            for case in detect_cases():
                if args.only and f"{case.quantity}:{case.noise}:{case.sigma:g}" not in args.only:
                    continue
                trials = list(pool.map(detect_trial, [(case, 5000 + i) for i in range(args.trials)]))
                found = [t for t in trials if t["found"]]
                errors = np.array([e for t in found for e in t["errors"]])
                wanted = case.change == "at"
                n_found = max(1, len(found))
                row = {"commit": commit(), "mode": "detect", **case.__dict__, "trials": len(trials),
                       "within_3_days": sum(t["delay_days"] <= 2 for t in found) / len(trials),
                       "paged": sum(t["paged"] for t in found) / len(trials),
                       "attributed_right": sum(t["names_change"] == wanted for t in found) / n_found,
                       "date_within_1_day": sum(abs(t["date_error_days"]) <= 1 for t in found) / n_found,
                       "size_rms_z": float(np.sqrt(np.mean(errors**2))) if errors.size else None,
                       "seconds": round(time.perf_counter() - t0)}  # fmt: skip
                emit(row, args.rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
