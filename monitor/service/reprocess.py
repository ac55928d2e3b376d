"""``crisgeo reprocess``: assess a whole period on a Dask cluster; this process alone writes the store.

One task per satellite-day runs :func:`monitor.assessment.compute_day` (list, fingerprint, select,
fetch, assess) on a worker and returns its :class:`~monitor.assessment.DayWork`; the client records each
as it arrives with :func:`monitor.service.pipeline.record_day`, the path of the daily run (ledger row, results
and outbox lines in one transaction). Days already done (``ok``, or found empty for good) are skipped unless
forced, so a second call does nothing and an interrupted call resumes. SIGINT/SIGTERM cancel what is
still queued or running; what finished is recorded.
"""

from __future__ import annotations

import datetime as dt
import logging
import signal
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from monitor.archive.configured import make_source
from monitor.assessment import DayWork, ProgressLines, compute_day
from monitor.config.model import Config
from monitor.core.vocabulary import RunStatus
from monitor.service.allocator import reuse_freed_memory
from monitor.service.lock import InstanceLock
from monitor.service.pipeline import RunOutcome, record_day
from monitor.service.store.sqlite import Store
from monitor.service.timetable import no_data_horizon

if TYPE_CHECKING:
    from distributed import Client, LocalCluster

LOG = logging.getLogger(__name__)


def day_task(cfg: Config, satellite: str, day: dt.date) -> DayWork:
    """One satellite-day on a worker: its own source (a NODD source shares ``cache_dir`` when that is on
    a shared file system), no store. The worker's allocator keeps freed memory for the next array, as in
    every crisgeo command (Dask starts its workers with MALLOC_TRIM_THRESHOLD_ = 64 KiB, which has the
    kernel zero fresh pages for every large array: ~10 % of a day's time).

    Parameters
    ----------
    cfg : Config
        The configuration.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.

    Returns
    -------
    DayWork
        What the day produced, for the client to record.
    """
    reuse_freed_memory()
    return compute_day(cfg, make_source(cfg), satellite, day)


@dataclass
class ReprocessSummary:
    """What a reprocessing call did: days per status, days skipped as already done, days not finished."""

    planned: int = 0
    skipped_done: int = 0
    statuses: dict = field(default_factory=dict)
    unfinished: int = 0
    wall_s: float = 0.0

    @property
    def finished(self) -> int:  # numpydoc ignore=RT01
        """Satellite-days processed and recorded by this call."""
        return sum(self.statuses.values())

    def lines(self) -> list[str]:
        """The summary printed at the end.

        Returns
        -------
        list of str
            Days per status, skipped, per hour, and left to do.
        """
        rate = self.finished / (self.wall_s / 3600) if self.wall_s > 0 and self.finished else 0.0
        out = [
            f"satellite-days: {self.planned} in the period, {self.skipped_done} already done (skipped), "
            f"{self.finished} processed in {self.wall_s:.0f} s ({rate:.0f} days/hour)"
        ]
        if self.statuses:
            out.append("  " + ", ".join(f"{k} {v}" for k, v in sorted(self.statuses.items())))
        if self.unfinished:
            out.append(f"  {self.unfinished} not finished (stopped): run the same command again to resume")
        return out


def period_days(since: dt.date, until: dt.date) -> list[dt.date]:
    """The days from *since* to *until*, both included.

    Parameters
    ----------
    since, until : datetime.date
        The first and last day.

    Returns
    -------
    list of datetime.date
        Every day, inclusive.
    """
    if until < since:
        raise ValueError(f"--until {until} is before --since {since}")
    return [since + dt.timedelta(days=k) for k in range((until - since).days + 1)]


def _client(scheduler: str | None, workers: int) -> tuple[Client, LocalCluster | None]:
    """A Dask client: of the scheduler at *scheduler*, or of a local cluster of *workers* processes with
    one thread each (the assessment's own threads are set per task)."""
    from distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler, timeout="30s"), None
    logging.getLogger("distributed").setLevel(logging.WARNING)  # its INFO lines would drown the days'
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.WARNING,
    )
    return Client(cluster), cluster


def reprocess(
    cfg: Config,
    since: dt.date,
    until: dt.date,
    satellites: list[str],
    scheduler: str | None = None,
    workers: int = 2,
    force: bool = False,
    progress: Callable[[RunOutcome], None] | None = None,
    stop: threading.Event | None = None,
) -> ReprocessSummary:
    """Assess every satellite-day of the period not yet done (all with *force*) on Dask and record each.

    *progress*, called with each recorded :class:`~monitor.service.pipeline.RunOutcome`; *stop*, an event that
    ends the call cleanly (queued and running days are cancelled and stay to do).

    Parameters
    ----------
    cfg : Config
        The configuration.
    since, until : datetime.date
        The period, inclusive.
    satellites : list of str
        The satellites.
    scheduler : str, optional
        A running Dask scheduler's address; else a local cluster.
    workers : int, optional
        Processes of the local cluster.
    force : bool, optional
        Redo the days already done.
    progress : callable, optional
        Called with each recorded outcome.
    stop : threading.Event, optional
        Ends the call cleanly: queued and running days are cancelled and stay to do.

    Returns
    -------
    ReprocessSummary
        What was done.
    """
    from distributed import wait

    stop = stop or threading.Event()
    summary = ReprocessSummary()
    t0 = time.monotonic()
    task_cfg = cfg.model_copy(update={"assessment": cfg.assessment.model_copy(update={"workers": 1})})
    with InstanceLock(cfg.state_dir, "reprocess"), Store(cfg.store.path) as store:
        store.interrupt_stale_runs()
        todo = []
        s = cfg.schedule
        today = dt.datetime.now(dt.timezone.utc).date()
        horizon = no_data_horizon(s, today)
        for sat in satellites:
            done = store.done_days(sat, horizon)  # as the daily run: ok, or no data for good
            for day in period_days(since, until):
                summary.planned += 1
                if day in done and not force:
                    summary.skipped_done += 1
                else:
                    todo.append((sat, day))
        if not todo:
            summary.wall_s = time.monotonic() - t0
            return summary
        client, cluster = _client(scheduler, workers)
        try:
            pending = {
                client.submit(day_task, task_cfg, s, d, pure=False, key=f"crisgeo-{s}-{d}"): (s, d)
                for s, d in todo
            }
            while pending and not stop.is_set():
                try:
                    done, _ = wait(list(pending), timeout=0.5, return_when="FIRST_COMPLETED")
                except TimeoutError:  # none finished yet: look at the stop event again
                    continue
                for fut in done:
                    sat, day = pending.pop(fut)
                    try:
                        work = fut.result()
                    except Exception as exc:  # noqa: BLE001 - a worker lost or crashed: the day failed
                        work = DayWork(
                            sat, day, RunStatus.FAILED, f"worker: {type(exc).__name__}: {exc}"[:1000]
                        )
                    out = record_day(cfg, store, store.begin_run(sat, day), work, today)
                    summary.statuses[out.status] = summary.statuses.get(out.status, 0) + 1
                    LOG.info("%s", out.summary())
                    if progress is not None:
                        progress(out)
            summary.unfinished = len(pending)
            if pending:
                client.cancel(list(pending))
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    summary.wall_s = time.monotonic() - t0
    return summary


def run_reprocess(
    cfg: Config,
    since: dt.date,
    until: dt.date,
    satellites: list[str],
    scheduler: str | None = None,
    workers: int = 2,
    force: bool = False,
) -> ReprocessSummary:
    """``crisgeo reprocess``: :func:`reprocess` with SIGINT/SIGTERM as a clean stop and a progress bar on a
    terminal (log lines otherwise).

    Parameters
    ----------
    cfg : Config
        The configuration.
    since, until : datetime.date
        The period, inclusive.
    satellites : list of str
        The satellites.
    scheduler : str, optional
        A running Dask scheduler's address.
    workers : int, optional
        Processes of the local cluster.
    force : bool, optional
        Redo the days already done.

    Returns
    -------
    ReprocessSummary
        What was done.
    """
    import sys

    stop = threading.Event()
    previous = {s: signal.signal(s, lambda *_: stop.set()) for s in (signal.SIGINT, signal.SIGTERM)}
    total = len(satellites) * len(period_days(since, until))
    bar = None
    if sys.stderr.isatty():
        from tqdm import tqdm

        bar = tqdm(total=total, unit="day", desc="reprocessing")
        progress = lambda _out: bar.update(1)  # noqa: E731
    else:
        progress = ProgressLines("reprocessed satellite-days", total, every_s=60)
    try:
        return reprocess(cfg, since, until, satellites, scheduler, workers, force, progress, stop)
    finally:
        if bar is not None:
            bar.close()
        for s, h in previous.items():
            signal.signal(s, h)
