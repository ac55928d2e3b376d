"""What the daily alert evaluation, the status, the report and the export cost as the history grows.

    .venv/bin/python -m benchmarks.history_growth --years 1 10 [--keep DIR] [--rows FILE]

For each length, a store is filled for three satellites with synthetic daily results
(:func:`monitor.simulate.history.fill_store`, a cross-track step ten days before the last day, so that the
jump rule has something to find), then timed on the day after its last:

* ``evaluate``: :func:`alerts.engine.evaluate` for the three satellites, the median of five calls after a
  first (which pays once for the simulated thresholds a daemon keeps between days, and for the noise fits the
  store keeps);
* ``refit``: the same on a copy of the filled store, the thresholds known: what a day costs when the jump
  rule fits its noise anew (once per refit date, or after a reprocessing);
* ``status``: :func:`monitor.service.status.status_report`;
* ``report``: :func:`monitor.service.outputs.report.html.build_report` (every satellite, the whole period);
* ``export``: :func:`monitor.service.outputs.export.export` of one satellite's whole history to NetCDF.

It prints CPU and wall seconds of each, and the findings' fingerprints with a digest of what they say, so
that two versions of the code can be checked to find the same. ``--keep DIR`` keeps the filled stores there
and reuses them on the next run.
"""

from __future__ import annotations

import argparse
import datetime as dt
import hashlib
import json
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from alerts.engine import evaluate, findings_for
from benchmarks.provenance import commit, emit
from monitor.config.alert_settings import AlertSettings
from monitor.config.model import Config
from monitor.service.outputs.export import export
from monitor.service.outputs.report.html import ReportOptions, build_report
from monitor.service.status import status_report
from monitor.service.store.sqlite import Store
from monitor.simulate.history import fill_store

SATELLITES = ["npp", "j01", "j02"]
FIRST = dt.date(2016, 1, 1)


def filled(work: Path, years: int) -> tuple[Path, dt.date]:
    """The store of *years* years under *work* (filled once), and its last day.

    Parameters
    ----------
    work : Path
        The folder the stores are kept in.
    years : int
        The history's length, years.

    Returns
    -------
    path : Path
        The store's file.
    last : datetime.date
        Its last day.
    """
    days = 365 * years
    path = work / f"history-{years}y.sqlite"
    last = FIRST + dt.timedelta(days=days - 1)
    if not path.exists():
        part = path.with_suffix(".part")
        part.unlink(missing_ok=True)
        store = Store(part)
        fill_store(store, SATELLITES, FIRST, days, step_day=days - 10, step_urad=60.0)
        store.close()
        part.replace(path)
    return path, last


def timed(what: Callable[[], Any]) -> tuple[float, float, Any]:
    """CPU and wall seconds of calling *what*, and what it returned.

    Parameters
    ----------
    what : callable
        Called without arguments.

    Returns
    -------
    cpu_s, wall_s : float
        Seconds.
    value : object
        Its return value.
    """
    c0, w0 = time.process_time(), time.perf_counter()
    value = what()
    return time.process_time() - c0, time.perf_counter() - w0, value


def digest(store: Store, settings: AlertSettings, now: dt.datetime) -> tuple[list[str], str]:
    """The findings' fingerprints at *now*, and a digest of their severities, summaries and lines.

    Parameters
    ----------
    store : Store
        The store.
    settings : AlertSettings
        The rules.
    now : datetime.datetime
        Now, UTC.

    Returns
    -------
    fingerprints : list of str
        One per finding.
    digest : str
        SHA-256 of what they say, 12 hex digits.
    """
    found = [f for sat in SATELLITES for f in findings_for(store, sat, settings, now)]
    said = json.dumps([[f.alert_id, f.severity, f.summary, f.lines] for f in found])
    return [f.alert_id for f in found], hashlib.sha256(said.encode()).hexdigest()[:12]


def measure(work: Path, years: int) -> dict:
    """Fill (or reuse) the store of *years* years, copy it, and time the four readers on it.

    Parameters
    ----------
    work : Path
        The folder the stores are kept in.
    years : int
        The history's length, years.

    Returns
    -------
    dict
        One row: seconds per reader, the findings and their digest.
    """
    t0 = time.perf_counter()
    kept, last = filled(work, years)
    fill_s = time.perf_counter() - t0
    path = work / f"run-{years}y.sqlite"
    shutil.copy(kept, path)  # evaluate writes its alert state: each run starts from the filled store
    store = Store(path)
    settings = AlertSettings()
    config = Config.model_validate(
        {"satellites": SATELLITES, "state_dir": str(work), "source": {"kind": "local", "path": str(work)}}
    )
    now = dt.datetime.combine(last + dt.timedelta(days=1), dt.time(6), dt.timezone.utc)
    row: dict[str, Any] = {"years": years, "satellites": len(SATELLITES), "fill_s": round(fill_s, 1)}
    fingerprints, said = digest(store, settings, now)
    row["findings"], row["digest"] = fingerprints, said
    timed(lambda: evaluate(store, settings, SATELLITES, now))  # the thresholds, once per process
    runs = [timed(lambda: evaluate(store, settings, SATELLITES, now))[:2] for _ in range(5)]
    row["evaluate_cpu_s"], row["evaluate_wall_s"] = (
        round(float(np.median(x)), 3) for x in zip(*runs, strict=True)
    )
    for name, call in (
        ("status", lambda: status_report(config, store, SATELLITES, now)),
        (
            "report",
            lambda: build_report(store, work / f"report-{years}y", ReportOptions(satellites=SATELLITES)),
        ),
        ("export", lambda: export(store, "j01", work / f"j01-{years}y.nc")),
    ):
        cpu, wall, _ = timed(call)
        row[f"{name}_cpu_s"], row[f"{name}_wall_s"] = round(cpu, 3), round(wall, 3)
    store.close()
    path.unlink()
    shutil.copy(kept, path)  # no fit kept yet: the rule fits the whole history before its refit dates
    store = Store(path)
    cpu, wall, _ = timed(lambda: evaluate(store, settings, SATELLITES, now))
    row["refit_cpu_s"], row["refit_wall_s"] = round(cpu, 3), round(wall, 3)
    store.close()
    path.unlink()
    return row


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--years", type=int, nargs="+", default=[1, 10], help="history lengths, years")
    p.add_argument("--keep", type=Path, help="keep the filled stores in this folder and reuse them")
    p.add_argument("--rows", type=Path, help="append the rows (JSON lines) to this file; printed in any case")
    args = p.parse_args(argv)
    work = args.keep or Path(tempfile.mkdtemp(prefix="crisgeo-history-"))
    work.mkdir(parents=True, exist_ok=True)
    rows = []
    try:
        for years in args.years:
            row = measure(work, years)
            rows.append(row)
            print(
                f"{years:2d} years x {row['satellites']} satellites: "
                + ", ".join(
                    f"{k} {row[f'{k}_cpu_s']:.2f} CPU-s ({row[f'{k}_wall_s']:.2f} s)"
                    for k in ("evaluate", "refit", "status", "report", "export")
                )
                + f"; findings {len(row['findings'])} ({row['digest']}): {', '.join(row['findings'])}",
                flush=True,
            )
        if len(rows) > 1:
            base = rows[0]["evaluate_cpu_s"]
            for r in rows[1:]:
                print(
                    f"evaluate at {r['years']} years / at {rows[0]['years']}: "
                    f"{r['evaluate_cpu_s'] / base:.2f}"
                )
        for r in rows:
            emit({**r, "commit": commit()}, str(args.rows) if args.rows else None)
        return 0
    finally:
        if args.keep is None:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
