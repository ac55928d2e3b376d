"""Reprocessing throughput on a Dask LocalCluster: satellite-days per hour with 1 and 2 workers, the
per-worker efficiency, and what a mission reprocessing (10 years x 3 satellites) would take.

The days are simulated and the kernels compiled first (not timed: numba keeps them on disk for the
workers); the simulated days go into one directory that every run reads; each run then
reprocesses them from an empty store with ``crisgeo reprocess``'s function (one Dask task per
satellite-day: list, fingerprint, select, fetch, assess; the client records each day). Every worker
runs the assessment on one thread, so N workers use N cores.

    .venv/bin/python benchmarks/reprocess.py [--days 4] [--granules 4] [--workers 1 2] [--keep DIR]
"""

from __future__ import annotations

import argparse
import datetime as dt
import os
import shutil
import tempfile
import time
from pathlib import Path

from monitor.archive.local import SimulatedSource
from monitor.collocation.collocate import warm_up
from monitor.config.file import load_config
from monitor.config.model import Config
from monitor.service.reprocess import period_days, reprocess

FIRST_DAY = dt.date(2024, 3, 1)
MISSION_SATELLITE_DAYS = 3 * 3653  # 10 years of S-NPP, NOAA-20 and NOAA-21


def _config(root: Path, name: str, granules: int) -> Config:
    path = root / f"{name}.yaml"
    path.write_text(
        f"satellites: [j01]\nstate_dir: {root / name}\n"
        f"source: {{kind: simulated, granules: {granules}}}\nscenes: {{keep: {granules}}}\n"
    )
    return load_config(path)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--days", type=int, default=4)
    ap.add_argument("--granules", type=int, default=4, help="CrIS granules per day (the daily run keeps 14)")
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--keep", help="directory for the simulated days (kept; reused when present)")
    args = ap.parse_args(argv)
    root = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="crisgeo-reprocess-"))
    root.mkdir(parents=True, exist_ok=True)
    days = period_days(FIRST_DAY, FIRST_DAY + dt.timedelta(days=args.days - 1))
    base = _config(root, "simulated", args.granules)
    t0 = time.perf_counter()
    source = SimulatedSource(base.state_dir / "simulated", base.source)
    for day in days:
        source.list_day("j01", day, ("GCRSO",))
    print(f"{args.days} days of {args.granules} CrIS granules simulated in {time.perf_counter() - t0:.0f} s")
    print(f"machine: {os.cpu_count()} cores")
    # numba's on-disk cache, filled here, so that no timed worker compiles the kernels
    print(f"kernels compiled or loaded in {warm_up():.1f} s (not timed)")
    rates = {}
    for n in args.workers:
        cfg = _config(root, f"w{n}", args.granules)
        shutil.rmtree(cfg.state_dir, ignore_errors=True)
        cfg.state_dir.mkdir(parents=True)
        (cfg.state_dir / "simulated").symlink_to(base.state_dir / "simulated")
        t0 = time.perf_counter()
        summary = reprocess(cfg, days[0], days[-1], ["j01"], workers=n)
        wall = time.perf_counter() - t0
        rates[n] = len(days) / (wall / 3600)
        print(
            f"{n} worker(s): {len(days)} days in {wall:.0f} s = {rates[n]:.0f} days/hour "
            f"({', '.join(f'{k} {v}' for k, v in sorted(summary.statuses.items()))})"
        )
    one = rates.get(1)
    for n, rate in sorted(rates.items()):
        if one and n > 1:
            print(f"efficiency at {n} workers: {rate / (n * one):.2f} (days/hour per worker over 1 worker's)")
    best_n = max(rates, key=lambda n: rates[n])
    per_worker = rates[best_n] / best_n
    print(
        f"10 years x 3 satellites = {MISSION_SATELLITE_DAYS} satellite-days of {args.granules} granules: "
        f"{MISSION_SATELLITE_DAYS / rates[best_n]:.0f} h with {best_n} worker(s) here, "
        f"{MISSION_SATELLITE_DAYS / (per_worker * 64):.0f} h on 64 workers at this per-worker rate"
    )
    if not args.keep:
        shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
