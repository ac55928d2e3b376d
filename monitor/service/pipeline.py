"""The daily run for one satellite-day: its assessment (one call, :func:`monitor.assessment.compute_day`),
recorded in the store and published.

Idempotent: a day's results are replaced in one transaction, never duplicated. Each run is a row in
the ledger (``runs``): ok, no_data (recorded, with the reason), failed, interrupted. Days without an
ok or no_data run within the catch-up window are redone, oldest first.
"""

from __future__ import annotations

import datetime as dt
import logging
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

from monitor.archive import Source
from monitor.assessment import (
    Assessor,
    DayAssessment,
    DayFingerprint,
    DayPrint,
    DayWork,
    RunCounts,
    compute_day,
)
from monitor.config.model import Config
from monitor.config.schedule import ScheduleConfig
from monitor.core import logcontext
from monitor.core.errors import DataError
from monitor.core.result import AssessmentResult, DayPrecision, worst_for
from monitor.core.vocabulary import EventKind, RunStatus
from monitor.history.changes import all_changes
from monitor.service.outputs.timeseries import change_lines, day_lines, drain_outbox, target_name
from monitor.service.store.sqlite import Store
from monitor.service.timetable import catch_up, no_data_horizon

LOG = logging.getLogger(__name__)


@dataclass
class RunOutcome:
    """What one satellite-day run did: the day as computed (:class:`~monitor.assessment.DayWork`, the one
    type that carries it from the science to the store), the ledger's run, and the status and reason as
    recorded (an empty day becomes final past its horizon)."""

    work: DayWork
    run_id: int | None = None
    status: RunStatus = RunStatus.OK
    reason: str | None = None

    @property
    def satellite(self) -> str:  # numpydoc ignore=RT01
        """The satellite's short name."""
        return self.work.satellite

    @property
    def day(self) -> dt.date:  # numpydoc ignore=RT01
        """The UTC day."""
        return self.work.day

    @property
    def result(self) -> AssessmentResult | None:  # numpydoc ignore=RT01
        """The day's result (an ok run's)."""
        return self.work.result

    @property
    def timings(self) -> dict:  # numpydoc ignore=RT01
        """Seconds per stage."""
        return self.work.timings

    @property
    def counts(self) -> RunCounts:  # numpydoc ignore=RT01
        """Granules listed, selected, assessed; files and bytes fetched."""
        return self.work.counts

    @property
    def precision(self) -> DayPrecision | None:  # numpydoc ignore=RT01
        """How far the batches went, and why they stopped."""
        return self.work.precision

    def summary(self) -> str:
        """The one line a run leaves in the log.

        Returns
        -------
        str
            The day's one summary line.
        """
        c, t = self.counts, self.timings
        parts = [
            f"run {self.satellite} {self.day}: {self.status}" + (f" ({self.reason})" if self.reason else "")
        ]
        parts.append(
            f"granules listed {c.listed}, selected {c.selected}, assessed {c.assessed}; {c.downloaded} files "
            f"whole, {c.bytes / 1e6:.0f} MB downloaded in {c.requests} requests"
            + (f" ({c.bytes / 1e6 / c.assessed:.0f} MB per assessed granule)" if c.assessed else "")
        )
        if self.result is not None:
            ok = [f for f in self.result.fors if f.reliable]
            worst = worst_for(ok)
            parts.append(
                f"reliable FORs {len(ok)}/{len(self.result.fors)}, worst "
                + ("-" if worst is None else f"{worst.worst_km:.2f} km (FOR {worst.for_index})")
            )
        if self.precision is not None:
            parts.append(self.precision.text())
        if t:
            parts.append("stages " + ", ".join(f"{k} {v:.1f} s" for k, v in t.items()))
        return "; ".join(parts)


def days_to_run(store: Store, satellite: str, schedule: ScheduleConfig, today: dt.date) -> list[dt.date]:
    """The days of the catch-up window (ending ``lag_days`` before *today*) without a completed run, oldest
    first. A day found empty (archive outage, late ingest) is tried again for ``no_data_retry_days`` after
    it became due; then its empty listing is final.

    Parameters
    ----------
    store : Store
        The service's store.
    satellite : str
        The satellite's short name.
    schedule : ScheduleConfig
        The ``schedule`` section.
    today : datetime.date
        Today, UTC.

    Returns
    -------
    list of datetime.date
        The days to run, oldest first.
    """
    return catch_up(schedule, store.done_days(satellite, no_data_horizon(schedule, today)), today)


def record_fingerprint(
    cfg: Config, store: Store, satellite: str, day: dt.date, fingerprint: DayFingerprint
) -> dict:
    """Compare the day's *fingerprint* with the previous day's print in the store, and store it.

    A step becomes a ``change:cris`` event (used for jump attribution and notified by the alerts).

    Parameters
    ----------
    cfg : Config
        The configuration.
    store : Store
        The service's store.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.
    fingerprint : DayFingerprint
        The day's fingerprint.

    Returns
    -------
    dict
        The verdict as the run's summary records it.
    """
    prev = store.fingerprint(satellite, day)
    reference = DayPrint.from_dict(prev[1]) if prev else None
    verdict = fingerprint.verdict(cfg.fingerprint.threshold_urad, reference, day)
    body = verdict.day.to_dict()
    if verdict.matches:
        body["ep_match"] = [m.to_dict() for m in verdict.matches[:3]]
    change = verdict.change
    if change is not None:
        desc = change.describe(verdict.matches)
        body["change"] = change.to_dict()
        store.add_event(
            EventKind.CHANGE_CRIS,
            satellite,
            {"time": change.time, "kind": "processing_change", "description": desc, "origin": "fingerprint"},
        )
        LOG.warning("%s %s: %s", satellite, day, desc)
    store.save_fingerprint(satellite, day, body)
    return body


def publish_changes(cfg: Config, store: Store, satellite: str) -> None:
    """Queue every known change of *satellite* for the time-series stores (dashboard annotations).

    Parameters
    ----------
    cfg : Config
        The configuration.
    store : Store
        The service's store.
    satellite : str
        The satellite's short name.
    """
    if not cfg.store.publish:
        return

    try:
        changes = all_changes(store, satellite, cfg.events_file)
    except (ValueError, OSError) as exc:
        LOG.warning("changes not published: %s", exc)
        return
    for p in cfg.store.publish:
        store.queue_lines(target_name(p), satellite, change_lines(p.measurement, changes))


def mapping_path(mapping_dir: Path, satellite: str, day: dt.date) -> Path:
    """Where a day's mapping is written: ``mapping_dir/SATELLITE/SATELLITE_DAY.nc``.

    Parameters
    ----------
    mapping_dir : Path
        The configuration's ``mapping_dir``.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.

    Returns
    -------
    Path
        The file.
    """
    return mapping_dir / satellite / f"{satellite}_{day.isoformat()}.nc"


def write_mapping(mapping_dir: Path, w: DayWork) -> None:
    """Write a day's mapping (a full disk or a missing xarray is a warning: the day's results are stored).

    Parameters
    ----------
    mapping_dir : Path
        The configuration's ``mapping_dir``.
    w : DayWork
        The day, with its mapping.
    """
    assert w.mapping is not None
    path = mapping_path(mapping_dir, w.satellite, w.day)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        w.mapping.write(path)
        LOG.info("wrote the day's mapping %s", path)
    except (OSError, ImportError, ValueError) as exc:
        LOG.warning("the day's mapping was not written to %s: %s", path, exc)


def record_day(cfg: Config, store: Store, run_id: int, w: DayWork, today: dt.date) -> RunOutcome:
    """Write what :func:`compute_day` produced under the ledger row *run_id*: the fingerprint, then the
    day's results and their outbox lines in one transaction (ok), or the empty, failed or interrupted
    run with its reason; then drain the outbox.

    Parameters
    ----------
    cfg : Config
        The configuration.
    store : Store
        The service's store.
    run_id : int
        The ledger's run.
    w : DayWork
        What the day's computing produced.
    today : datetime.date
        Today, UTC (the no-data horizon).

    Returns
    -------
    RunOutcome
        The outcome.
    """
    t1 = time.perf_counter()
    try:
        if w.fingerprint is not None:
            try:
                record_fingerprint(cfg, store, w.satellite, w.day, w.fingerprint)
            except (DataError, OSError, ValueError) as exc:
                LOG.warning("fingerprint of %s %s not recorded: %s", w.satellite, w.day, exc)
        out = RunOutcome(w, run_id, w.status, w.reason)
        if w.status == RunStatus.OK and w.result is not None:  # an ok day always has its result
            queued = day_lines(cfg.store.publish, w.satellite, w.day, w.result)
            store.save_day(run_id, w.satellite, w.day, w.result, w.decisions, queued, w.precision)
            publish_changes(cfg, store, w.satellite)
            if w.mapping is not None and cfg.mapping_dir is not None:
                write_mapping(cfg.mapping_dir, w)
        elif w.status == RunStatus.NO_DATA:
            s = cfg.schedule
            if w.day < no_data_horizon(s, today):
                out.status = RunStatus.NO_DATA_FINAL
            else:
                out.reason = f"{out.reason} (tried again for {s.no_data_retry_days} day(s) after it is due)"
            summary = {"selection": [asdict(d) for d in w.decisions[:50]]} if w.decisions else None
            store.finish_run(run_id, out.status, out.reason, summary=summary)
        elif w.status == RunStatus.FAILED:
            store.finish_run(run_id, RunStatus.FAILED, w.reason)
            store.add_event(EventKind.RUN_FAILED, w.satellite, {"day": w.day.isoformat(), "reason": w.reason})
        else:
            store.finish_run(run_id, w.status, w.reason)
        return out
    finally:
        if cfg.store.publish:
            drain_outbox(store, cfg.store.publish)
        w.timings["publish"] = time.perf_counter() - t1


def run_day(
    cfg: Config,
    store: Store,
    source: Source,
    satellite: str,
    day: dt.date,
    today: dt.date,
    should_stop: Callable[[], bool] | None = None,
    progress: Callable[[object], None] | None = None,
    assessor: Assessor = DayAssessment,
) -> RunOutcome:
    """Process one satellite-day end to end (:func:`compute_day`, then :func:`record_day`) as of *today*
    (the no-data horizon); every outcome is recorded in the ledger, an unexpected exception too
    (``failed`` with its type and message).

    Parameters
    ----------
    cfg : Config
        The configuration.
    store : Store
        The service's store.
    source : Source
        Where the granules come from.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.
    today : datetime.date
        Today, UTC (the no-data horizon).
    should_stop : callable, optional
        Polled between steps.
    progress : callable, optional
        Called after each granule assessed.
    assessor : Assessor, optional
        What assesses the batches (:class:`DayAssessment`).

    Returns
    -------
    RunOutcome
        The outcome, recorded.
    """
    run_id = store.begin_run(satellite, day)
    with logcontext.context(satellite=satellite, day=day.isoformat(), run_id=run_id):
        work = compute_day(cfg, source, satellite, day, should_stop, progress, assessor)
        with logcontext.context(stage="record"):
            outcome = record_day(cfg, store, run_id, work, today)
        store.record_stages(run_id, outcome.timings)
        return outcome
