"""Detection quality of the jump rule on generated daily series, with the default settings.

Series: the paper's per-FOR offset profile in km plus day-to-day scatter like the paper's per-case
spread (in-track 0.12 km; cross-track 0.12 km at nadir growing to 0.37 km at the scan ends; AR(1)
0.3), 30 FORs. Detection runs day by day as the service would (each evaluation sees the data up to
that day, which arrives one day late).

* Jumps: a step of the given size at a change date, in a random group of FORs (10 adjacent FORs, or
  all), in-track or cross-track, from a CrIS or a VIIRS change; the calendar also holds changes that
  move nothing. Reported: the fraction found within 3 days, and attributed to the right instrument.
* False alarms: a year of noise-only series per satellite (with the inert changes still in the
  calendar): distinct jump alerts raised.

    .venv/bin/python benchmarks/jump_detection.py [--trials 200] [--years 3] [--jump-km 0.3]
"""

from __future__ import annotations

import argparse
import datetime as dt
import sys

import numpy as np

from alerts.rules import COMPONENTS, detect_jumps
from monitor.config.alert_settings import RuleSettings
from monitor.history.changes import Change, preceding_change
from monitor.simulate.profiles import paper_profile

START = dt.date(2023, 1, 1)


def noise_series(rng: np.random.Generator, n_days: int) -> tuple[list[dt.date], dict[str, np.ndarray]]:
    """(days, {component: (n_days, 30) km}) of a stable instrument with realistic scatter."""
    k = np.arange(30)
    sig_in = np.full(30, 0.12)
    sig_cross = 0.12 + 0.25 * ((k - 14.5) / 14.5) ** 2
    d_alpha, d_beta = paper_profile()
    base = {
        "in_track_km": d_alpha * 1e-6 * 830.0,
        "cross_track_km": d_beta * 1e-6 * 830.0 / np.cos(np.radians((k - 14.5) * 3.33)) ** 2,
    }
    out = {}
    for comp, sig in (("in_track_km", sig_in), ("cross_track_km", sig_cross)):
        e = rng.normal(0, 1, (n_days, 30))
        for t in range(1, n_days):
            e[t] = 0.3 * e[t - 1] + np.sqrt(1 - 0.09) * e[t]
        out[comp] = base[comp] + e * sig
    return [START + dt.timedelta(days=i) for i in range(n_days)], out


def inert_changes(rng: np.random.Generator, n_days: int, satellite: str = "j01") -> list[Change]:
    """Calendar entries that change nothing in the geolocation (about six a year)."""
    days = sorted(rng.choice(np.arange(30, n_days), size=max(1, n_days // 60), replace=False))
    return [
        Change(
            dt.datetime.combine(START + dt.timedelta(days=int(d)), dt.time(12), dt.timezone.utc),
            satellite,
            rng.choice(["cris", "viirs"]),
            "software",
            "inert",
            "calendar",
        )
        for d in days
    ]


def alerts_day_by_day(
    days: list[dt.date],
    values: dict[str, np.ndarray],
    changes: list[Change],
    s: RuleSettings,
    start: int = 25,
) -> dict:
    """Every jump split day found by daily evaluations (data one day late), with the first day seen."""
    change_days = sorted({c.time.date() for c in changes})
    seen: dict[dt.date, tuple[dt.date, dict]] = {}
    for t in range(start, len(days)):
        sub = {c: v[: t + 1] for c, v in values.items()}
        for j in detect_jumps(days[: t + 1], sub, change_days, s):
            seen.setdefault(j["split"], (days[t] + dt.timedelta(days=1), j))
    return seen


def jump_trial(
    rng: np.random.Generator, jump_km: float, s: RuleSettings
) -> tuple[bool, bool, int | None]:
    n = 60
    days, values = noise_series(rng, n)
    event = 40
    instrument = rng.choice(["cris", "viirs"])
    comp = COMPONENTS[rng.integers(2)][0]
    group = [range(0, 10), range(10, 20), range(20, 30), range(30)][rng.integers(4)]
    values[comp][event:, list(group)] += jump_km * rng.choice([-1, 1])
    changes = inert_changes(rng, n) + [
        Change(
            dt.datetime.combine(days[event], dt.time(6), dt.timezone.utc),
            "j01",
            instrument,
            "ep_upload" if instrument == "cris" else "lut_change",
            "injected",
            "calendar",
        )
    ]
    changes = [
        c for c in changes if abs((c.time.date() - days[event]).days) > 12 or c.description == "injected"
    ]
    seen = alerts_day_by_day(days, values, changes, s, start=event - 5)
    hit = seen.get(days[event])
    if hit is None:
        return False, False, None
    delay = (hit[0] - days[event]).days
    attributed = preceding_change(changes, days[event], s.attribution_days)
    return delay <= 3, attributed is not None and attributed.instrument == instrument, delay


def false_alarms(rng: np.random.Generator, years: int, s: RuleSettings) -> list[int]:
    out = []
    for _ in range(years):
        days, values = noise_series(rng, 365 + 30)
        out.append(len(alerts_day_by_day(days, values, inert_changes(rng, 365 + 30), s, start=30)))
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--trials", type=int, default=200)
    p.add_argument("--years", type=int, default=3)
    p.add_argument("--jump-km", type=float, nargs="+", default=[0.3, 0.5])
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args()
    s = RuleSettings()
    rng = np.random.default_rng(args.seed)
    for jump in args.jump_km:
        res = [jump_trial(rng, jump, s) for _ in range(args.trials)]
        found = sum(r[0] for r in res)
        right = sum(r[0] and r[1] for r in res)
        delays = [r[2] for r in res if r[2] is not None]
        print(
            f"jump {jump:.2f} km: found within 3 days {found}/{args.trials} "
            f"({100 * found / args.trials:.1f} %), "
            f"attributed to the right instrument {right}/{found}; median delay "
            f"{np.median(delays) if delays else float('nan'):.0f} day(s)"
        )
    fa = false_alarms(rng, args.years, s)
    print(f"false alarms on noise-only years: {fa} (mean {np.mean(fa):.2f} per satellite-year)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
