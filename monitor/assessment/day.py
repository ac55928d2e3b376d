"""A satellite-day's assessment, from the source's listing to the typed result: list, fingerprint the GEO
files, rank the scenes, fetch and assess them in batches until the day's precision target or a budget.

This is the science's driver of a day; it touches no store. The service calls :func:`compute_day` once per
satellite-day (the daily run, a reprocessing worker) and records the :class:`DayWork` it returns. Never
raises for a problem of the day's data or source: it becomes the work's status and reason.
"""

from __future__ import annotations

import contextvars
import datetime as dt
import logging
import shutil
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from monitor.archive import ALL_PRODUCTS, ListedFile, Source, SourceError
from monitor.assessment.assess import DayAssessment, in_second_band
from monitor.assessment.daymap import band_plan, map_day, with_bands
from monitor.assessment.scenes import Candidate, batch_decisions, next_batch, rank_scenes
from monitor.config.assessment import AssessmentConfig
from monitor.config.model import Config
from monitor.core import logcontext
from monitor.core.errors import DataError, StopRequested
from monitor.core.result import SECOND_BAND, AssessmentResult, DayPrecision, SceneDecision
from monitor.core.vocabulary import DayStop, RunStatus
from monitor.mapping import fingerprint as fpr
from monitor.matchup import Matchup
from monitor.sdr import read_file
from monitor.sdr.engpkt import load_library
from monitor.sdr.pairing import CasePlan, GranuleFiles, assemble, granule_files
from monitor.sdr.products import CRIS_GEO

LOG = logging.getLogger(__name__)

# what assesses a day's fetched granules batch by batch, from (satellite, config, workers): the assessment,
# or a test's stand-in
Assessor = Callable[[str, AssessmentConfig, int], DayAssessment]


class NoRoom(OSError):
    """The file system of the state directory has less room than a satellite-day needs."""


def check_room(cfg: Config) -> None:
    """Refuse to begin a day when the state directory's file system has less room than a day needs.

    Raises :class:`NoRoom` naming the folder when the file system of ``state_dir`` (the store, the download
    cache, simulated granules) has less than ``min_free_mb`` free: the day is not begun, and is redone once
    there is room.

    Parameters
    ----------
    cfg : Config
        The service's configuration.
    """
    probe = next(p for p in (cfg.state_dir, *cfg.state_dir.parents) if p.exists())
    free_mb = shutil.disk_usage(probe).free / 2**20
    if free_mb < cfg.min_free_mb:
        raise NoRoom(
            f"{cfg.state_dir}: {free_mb:.0f} MB free, a day needs min_free_mb {cfg.min_free_mb}; the day is "
            "redone once there is room"
        )


class ProgressLines:
    """Progress of a long stage as log lines, for logs and the journal where no bar can be drawn.

    One line at most every *every_s* seconds, and one at the end. Call it once per item done.

    Parameters
    ----------
    what : str
        What is counted (``assessed granules``).
    total : int
        The items there will be.
    every_s : float, optional
        Seconds between lines at most.
    """

    def __init__(self, what: str, total: int, every_s: float = 30.0):
        self.what, self.total, self.every_s = what, total, every_s
        self.done = 0
        self.t0 = self.last = time.monotonic()

    def __call__(self, _item: object = None) -> None:
        self.done += 1
        now = time.monotonic()
        if self.done >= self.total or now - self.last >= self.every_s:
            self.last = now
            LOG.info("%s: %d/%d after %.0f s", self.what, self.done, self.total, now - self.t0)


class Heartbeat:
    """A line every *every_s* seconds while a satellite-day is computed, naming what it is doing.

    The stages without items to count (simulating the day's granules, the day's estimate after its granules
    are collocated) are otherwise silent for a minute and more. A context manager: the beat stops with it.

    Parameters
    ----------
    label : str
        The satellite-day the lines name (``j01 2026-11-21``).
    every_s : float, optional
        Seconds between lines.
    """

    def __init__(self, label: str, every_s: float = 15.0) -> None:
        self.label, self.every_s = label, every_s
        self.doing = "starting"
        self.t0 = time.monotonic()
        self._done = threading.Event()
        self._thread = threading.Thread(
            target=contextvars.copy_context().run, args=(self._beat,), name="heartbeat", daemon=True
        )

    def stage(self, name: str, doing: str) -> None:
        """Enter a stage.

        Parameters
        ----------
        name : str
            The stage (the lines' field: list, fingerprint, select, fetch, assess, estimate).
        doing : str
            What the heartbeat's lines say it is doing.
        """
        logcontext.stage(name)
        self.doing = doing

    def _beat(self) -> None:
        while not self._done.wait(self.every_s):
            LOG.info("%s: %s, %.0f s into the day", self.label, self.doing, time.monotonic() - self.t0)

    def __enter__(self) -> Heartbeat:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._done.set()
        self._thread.join()


@dataclass
class RunCounts:
    """What a satellite-day run handled: CrIS granules listed, selected and assessed; files downloaded
    whole, bytes read (files and ranges) and HTTP requests made."""

    listed: int = 0
    selected: int = 0
    assessed: int = 0
    downloaded: int = 0
    bytes: int = 0
    requests: int = 0


def day_fingerprint(
    cfg: Config, source: Source, satellite: str, day: dt.date, listing: list[ListedFile]
) -> fpr.DayFingerprint | None:
    """The LOS fingerprint of a sample of the day's GEO granules, with the EPs of the library identified.

    Parameters
    ----------
    cfg : Config
        The service's configuration.
    source : Source
        Where the day's granules come from.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.
    listing : list of ListedFile
        The day's listing.

    Returns
    -------
    DayFingerprint or None
        :func:`monitor.mapping.fingerprint.fingerprint_day` of the granules read; None without any (a granule
        that cannot be fetched or read is logged and left out).
    """
    geos = sorted(
        (f for f in listing if f.product in CRIS_GEO and f.parsed.start.date() == day),
        key=lambda f: f.parsed.start,
    )
    if not geos:
        return None
    picks = np.unique(
        np.round(np.linspace(0, len(geos) - 1, min(cfg.fingerprint.granules, len(geos)))).astype(int)
    )
    prints = []
    for i in picks:
        try:
            (g,) = read_file(source.fetch(geos[i]), kinds=("cris_geo",))[:1]
            prints.append(fpr.granule_print(g))
        except (SourceError, DataError) as exc:
            LOG.warning("fingerprint: skipping %s: %s", geos[i].name, exc)
    if not prints:
        return None
    library, problems = load_library(cfg.fingerprint.ep_library)
    for problem in problems:
        LOG.warning("fingerprint: EP library: %s", problem)
    return fpr.fingerprint_day(prints, library, satellite)


def fetch_plan(
    source: Source,
    satellite: str,
    chosen: list,
    stop: Callable[[], bool] = lambda: False,
    progress: Callable[[], None] | None = None,
) -> CasePlan:
    """The assessment plan of the chosen scenes, each VIIRS granule fetched and read once.

    Parameters
    ----------
    source : Source
        Where the day's granules come from.
    satellite : str
        The satellite's short name.
    chosen : list of Candidate
        The scenes chosen, their CrIS files as selection read them.
    stop : callable
        Polled between granules; True ends the work.
    progress : callable, optional
        Called after each file fetched.

    Returns
    -------
    CasePlan
        The paired granules; a VIIRS granule that cannot be fetched or read is skipped with its reason.
    """
    viirs: dict[str, GranuleFiles] = {}
    skipped: list[tuple[str, str]] = []
    for c in chosen:
        if stop():
            raise StopRequested
        for vs, vg in c.viirs:
            key = vg.parsed.granule_key
            if key in viirs or any(key == k for k, _ in skipped):
                continue
            try:
                viirs[key] = granule_files(key, source.fetch(vs), source.fetch(vg))
            except (SourceError, DataError) as exc:  # BudgetExceeded is a SourceError
                skipped.append((key, str(exc)))
        if progress is not None:
            progress()
    return assemble(satellite, [c.files for c in chosen], list(viirs.values()), skipped)


@dataclass
class DayWork:
    """What the computing half of a satellite-day produced, before anything is stored: picklable, so that
    a reprocessing worker returns it to the one process that writes the store."""

    satellite: str
    day: dt.date
    status: RunStatus  # ok, no_data, failed or interrupted
    reason: str | None = None
    result: AssessmentResult | None = None
    decisions: list[SceneDecision] = field(default_factory=list)
    fingerprint: fpr.DayFingerprint | None = None  # the GEO files' LOS fingerprint, EPs identified
    timings: dict = field(default_factory=dict)
    counts: RunCounts = field(default_factory=RunCounts)
    precision: DayPrecision | None = None  # how far the batches went, and why they stopped
    mapping: Matchup | None = None  # the day's CrIS FOVs mapped onto VIIRS (when mapping_dir is set)


def compute_day(
    cfg: Config,
    source: Source,
    satellite: str,
    day: dt.date,
    should_stop: Callable[[], bool] | None = None,
    progress: Callable[[object], None] | None = None,
    assessor: Assessor = DayAssessment,
) -> DayWork:
    """List, fingerprint, select, fetch and assess one satellite-day, touching no store.

    Its log lines carry the satellite, day and stage, and only its own: the context ends with it.

    Parameters
    ----------
    cfg : Config
        The service's configuration.
    source : Source
        Where the day's granules come from.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.
    should_stop : callable, optional
        Polled between steps; True ends the day as interrupted.
    progress : callable, optional
        Called after each granule assessed.
    assessor : Assessor, optional
        What assesses the batches: :class:`DayAssessment` unless a test gives its stand-in.

    Returns
    -------
    DayWork
        What the day produced, picklable for a reprocessing worker; a problem of the day's data or source
        becomes its status and reason, never an exception.
    """
    with (
        logcontext.context(satellite=satellite, day=day.isoformat()),
        Heartbeat(f"{satellite} {day}") as beat,
    ):
        return _compute_day(cfg, source, satellite, day, should_stop, progress, assessor, beat)


def _compute_day(
    cfg: Config,
    source: Source,
    satellite: str,
    day: dt.date,
    should_stop: Callable[[], bool] | None,
    progress: Callable[[object], None] | None,
    assessor: Assessor,
    beat: Heartbeat,
) -> DayWork:
    stop = should_stop or (lambda: False)
    w = DayWork(satellite, day, RunStatus.OK)
    t0 = time.perf_counter()
    try:
        beat.stage("list", "listing the day's granules")
        check_room(cfg)
        source.start_day(stop)
        listing = source.list_day(satellite, day, ALL_PRODUCTS)
        w.timings["list"] = time.perf_counter() - t0
        w.counts.listed = len(listing)
        if not any(f.product in CRIS_GEO for f in listing):
            w.status, w.reason = (
                RunStatus.NO_DATA,
                f"no CrIS GEO granule of {satellite} on {day} in the source",
            )
            return w
        if stop():
            raise StopRequested
        t1 = time.perf_counter()
        beat.stage("fingerprint", "reading the LOS fingerprint")
        w.fingerprint = day_fingerprint(cfg, source, satellite, day, listing)
        w.timings["fingerprint"] = time.perf_counter() - t1
        t1 = time.perf_counter()
        beat.stage("select", "ranking the scenes")
        ranked, w.decisions = rank_scenes(
            listing, source, satellite, cfg.scenes.candidates, cfg.scenes.min_inhomogeneity_k
        )
        w.timings["select"] = time.perf_counter() - t1
        if not ranked:
            w.status = RunStatus.NO_DATA
            w.reason = "no usable scene: " + "; ".join(sorted({d.reason for d in w.decisions}))[:500]
            return w
        cases: list[CasePlan] = []
        w.result, w.precision, decided = assess_in_batches(
            cfg, source, satellite, day, ranked, t0, w.timings, stop, progress, assessor, beat, cases
        )
        w.decisions += decided
        w.counts.selected = w.precision.granules
        w.counts.assessed = len(w.result.granules)
        if stop():
            raise StopRequested
        if w.result.granules:
            t1 = time.perf_counter()
            beat.stage("map", "mapping the CrIS FOVs onto VIIRS")
            mapped = {*cfg.assessment.bands, *(cfg.mapping_bands if cfg.mapping_dir is not None else ())}
            try:
                plan = band_plan(source, satellite, day, cases, tuple(sorted(mapped)))
                matchup = map_day(plan, w.result, tuple(mapped), stop)
                w.result = with_bands(w.result, matchup, cfg.assessment)
                w.mapping = matchup if cfg.mapping_dir is not None else None
                w.timings["map"] = time.perf_counter() - t1
                if SECOND_BAND in cfg.assessment.bands:
                    t1 = time.perf_counter()
                    beat.stage(SECOND_BAND, f"assessing the geolocation in {SECOND_BAND}")
                    w.result = in_second_band(plan, w.result, cfg.assessment, stop)
                    w.timings[SECOND_BAND] = time.perf_counter() - t1
            except (SourceError, DataError) as exc:  # the bands are a product of the day, not its outcome
                LOG.warning("the day's mapping failed: %s", exc)
                w.result.notes.append(f"no CrIS minus VIIRS per band: the mapping failed: {exc}")
                w.timings["map"] = time.perf_counter() - t1
    except StopRequested:
        w.status, w.reason, w.result = RunStatus.INTERRUPTED, "stop requested", None
    except NoRoom as exc:
        w.status, w.reason, w.result = RunStatus.FAILED, f"no room: {exc}", None
    except (SourceError, DataError, OSError) as exc:
        w.status, w.reason, w.result = RunStatus.FAILED, f"{type(exc).__name__}: {exc}", None
    except Exception as exc:  # noqa: BLE001 - the satellite-day boundary: record, alert, let the next day run
        LOG.exception("run %s %s failed unexpectedly", satellite, day)
        w.status, w.reason = RunStatus.FAILED, f"unexpected {type(exc).__name__}: {exc}"[:1000]
        w.result = None
    # read in place, the bytes travel while the day is assessed: counted once it ends, however it ends
    w.counts.downloaded, w.counts.bytes = source.downloaded_files, source.spent_bytes
    w.counts.requests = source.requests
    if w.precision is not None and w.counts.assessed:
        w.precision = replace(w.precision, mb_per_granule=w.counts.bytes / 1e6 / w.counts.assessed)
    return w


def assess_in_batches(
    cfg: Config,
    source: Source,
    satellite: str,
    day: dt.date,
    ranked: list[Candidate],
    started: float,
    timings: dict,
    stop: Callable[[], bool],
    progress: Callable[[object], None] | None,
    assessor: Assessor,
    beat: Heartbeat,
    cases: list[CasePlan] | None = None,
) -> tuple[AssessmentResult, DayPrecision, list[SceneDecision]]:
    """Fetch and assess the ranked candidates in batches until the day's sigma reaches its target or a budget
    ends.

    The day stops when its sigma (:meth:`AssessmentResult.day_sigma_urad`) reaches
    ``scenes.target_sigma_urad`` (without a target: one batch of ``scenes.keep``), ``scenes.max_granules`` are
    assessed, the candidates are spent, or not even ``scenes.keep`` more granules, each as costly as the
    costliest so far, fit in ``source.daily_budget_mb`` or ``schedule.run_budget_min``. Each batch after the
    first aims at the target (:func:`monitor.assessment.scenes.next_batch`).

    Parameters
    ----------
    cfg : Config
        The service's configuration.
    source : Source
        Where the day's granules come from.
    satellite : str
        The satellite's short name.
    day : datetime.date
        The UTC day.
    ranked : list of Candidate
        The candidates, the most informative per byte first.
    started : float
        The run's start, ``time.perf_counter()`` s, for ``schedule.run_budget_min``.
    timings : dict
        Gains the seconds of ``fetch`` and ``assess``.
    stop : callable
        Polled between granules; True ends the work.
    progress : callable, optional
        Called after each granule assessed.
    assessor : Assessor
        What assesses the batches.
    beat : Heartbeat
        Hears each stage.
    cases : list of CasePlan, optional
        Gains each batch's plan as fetched (the day's mapping reads them again).

    Returns
    -------
    result : AssessmentResult
        The estimate over every batch.
    precision : DayPrecision
        How far it went and why it stopped.
    decisions : list of SceneDecision
        Every candidate's decision.
    """
    s = cfg.scenes
    a = cfg.assessment
    with assessor(satellite, a, a.workers) as estimate:  # its spool removed at the end
        budget_bytes = cfg.source.daily_budget_mb * 1e6
        budget_s = cfg.schedule.run_budget_min * 60.0
        sizes: list[int] = []
        taken, size = 0, s.keep
        worst_s = worst_bytes = 0.0  # the costliest granule so far (its batch's cost over its count)
        label = f"{satellite} {day}"
        while True:
            batch = ranked[taken : taken + size]
            t1, bytes1 = time.perf_counter(), source.spent_bytes
            beat.stage("fetch", "fetching the scenes")
            case = fetch_plan(
                source, satellite, batch, stop, ProgressLines(f"{label}: fetched scenes", len(batch))
            )
            t2 = time.perf_counter()
            beat.stage("assess", "collocating the granules")
            LOG.info(
                "batch %d: assessing %d CrIS granule(s) against %d VIIRS granule(s)",
                len(sizes) + 1, len(case.cris), len(case.viirs_all),
            )  # fmt: skip
            begin = getattr(progress, "begin", None)  # a counter that shows totals learns the batch's
            if begin is not None:
                begin(len(case.cris))
            estimate.add(case, progress or ProgressLines(f"{label}: assessed granules", len(case.cris)), stop)
            if cases is not None:
                cases.append(case)
            beat.stage("estimate", "estimating the day's offsets")
            result = estimate.result()
            t3 = time.perf_counter()
            timings["fetch"] = timings.get("fetch", 0.0) + t2 - t1
            timings["assess"] = timings.get("assess", 0.0) + t3 - t2
            sizes.append(len(batch))
            taken += len(batch)
            worst_s = max(worst_s, (t3 - t1) / len(batch))
            worst_bytes = max(worst_bytes, (source.spent_bytes - bytes1) / len(batch))
            sigma = result.day_sigma_urad()
            if stop():
                raise StopRequested
            left = min(len(ranked), s.max_granules) - taken
            fit_bytes = (budget_bytes - source.spent_bytes) // worst_bytes if worst_bytes else left
            fit_s = (budget_s - (t3 - started)) // worst_s if worst_s else left
            if s.target_sigma_urad is None:
                why = DayStop.ONE_BATCH
            elif sigma is not None and sigma <= s.target_sigma_urad:
                why = DayStop.TARGET
            elif taken >= len(ranked):
                why = DayStop.CANDIDATES
            elif taken >= s.max_granules:
                why = DayStop.MAX_GRANULES
            elif fit_bytes < min(s.keep, left):
                why = DayStop.BYTES
            elif fit_s < min(s.keep, left):
                why = DayStop.TIME
            else:
                size = int(min(next_batch(taken, sigma, s.target_sigma_urad, s.keep), left, fit_bytes, fit_s))
                LOG.info(
                    "after %d granule(s) the day's sigma is %s urad; target %g: the next batch takes %d",
                    taken,
                    sigma,
                    s.target_sigma_urad,
                    size,
                )
                continue
            precision = DayPrecision(taken, len(sizes), sigma, s.target_sigma_urad, why)
            LOG.info("precision: %s", precision.text())
            return (
                result,
                precision,
                batch_decisions(ranked, sizes, f"the day stopped at {taken} ({why})"),
            )
