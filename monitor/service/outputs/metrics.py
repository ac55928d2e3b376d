"""Prometheus metrics of the daemon (prometheus-client), served at ``/metrics``.

What lives in the store (the run ledger, the latest per-FOR offsets, the alerts firing, the outbox) is read
at each scrape, so it survives restarts and agrees with ``crisgeo status``; what only the process knows
(downloads since start) is kept in its own counters. The process and platform collectors of
prometheus-client (``process_*``, ``python_*``) come along, and the endpoint negotiates the text and
OpenMetrics formats as prometheus-client's own handler does.

    crisgeo_last_success_timestamp_seconds{satellite}     end of the latest ok run, 0 if none yet
    crisgeo_watched_since_timestamp_seconds{satellite}    start of its first run (or of this process)
    crisgeo_runs_total{satellite,outcome}                 finished runs in the ledger by outcome (only grows)
    crisgeo_runs_in_progress{satellite}                   runs under way
    crisgeo_run_duration_seconds{satellite,stage}         stages of the latest run (from the store: kept
                                                          over a restart)
    crisgeo_downloaded_granules_total{satellite}          files downloaded whole by this process
    crisgeo_downloaded_bytes_total{satellite}             bytes downloaded by this process (files and ranges)
    crisgeo_nodd_requests_total{satellite}                HTTP requests to NODD by this process
    crisgeo_outbox_points{target}                         time-series points waiting to be sent
    crisgeo_alerts_firing{satellite,rule,severity}        alerts firing now
    crisgeo_for_offset_radians{satellite,for,direction}   latest day's LOS offset (alpha, beta)
    crisgeo_for_offset_meters{satellite,for,direction}    latest day's offset on the ground (in_track,
                                                          cross_track, total)
    crisgeo_for_beyond_spec{satellite,for}                1 when the FOR is beyond the specification (the
                                                          one rule:
                                                          monitor.core.result.ForOffset.spec_breaches)
    crisgeo_for_calibration_bias_kelvin{satellite,for}    latest CrIS - VIIRS bias at 280 K
    crisgeo_for_calibration_gain_ratio{satellite,for}     latest CrIS - VIIRS gain difference (0.01 = 1 %)
    crisgeo_for_response_full_width_radians{satellite,for,level}  the CrIS FOV response's full width
                                                          at level 0.5 / 0.1 of its peak, fitted per FOR
    crisgeo_for_reliable{satellite,for}                   1 when the FOR carries no reliability flag
    crisgeo_latest_day_timestamp_seconds{satellite}       00:00 UTC of the latest assessed day
    crisgeo_day_granules_assessed{satellite}              granules the latest ok run assessed
    crisgeo_day_sigma_radians{satellite}                  the median per-FOR sigma it reached (worse
                                                          direction: AssessmentResult.day_sigma_urad)
    crisgeo_day_target_sigma_radians{satellite}           its scenes.target_sigma_urad (absent: none)
    crisgeo_day_stop_info{satellite,reason}               1 on why it stopped (one_batch, target,
                                                          max_granules, candidates, bytes, time)
    crisgeo_healthy                                       1 when /healthz is ok
    crisgeo_build_info{version}                           always 1

Prometheus' conventions: base units in the names (seconds, meters, radians, kelvin, ratios), ``_total``
for counters, no ``_created`` series; the ``for`` label is zero-padded (``"01"``..``"30"``) as the
InfluxDB tag is, so that both sort. The code's own names keep their unit suffixes (``_km``, ``_urad``):
this is the one surface where the convention of its readers wins.

The dead-man's rule (configs/prometheus/crisgeo-rules.yml) takes the last success, or for a satellite that
never succeeded the time it has been watched since: a deployment that never works fires too.
"""

from __future__ import annotations

import datetime as dt
import math
from collections.abc import Callable, Iterable, Iterator
from typing import Protocol

from prometheus_client import (
    GC_COLLECTOR,
    PLATFORM_COLLECTOR,
    PROCESS_COLLECTOR,
    CollectorRegistry,
    Counter,
    Gauge,
    disable_created_metrics,
)
from prometheus_client.core import CounterMetricFamily, GaugeMetricFamily
from prometheus_client.metrics_core import Metric

from monitor.core.constants import URAD
from monitor.core.measures import Family
from monitor.core.result import DayPrecision, ForOffset, measures
from monitor.core.vocabulary import DayStop, RunStatus
from monitor.service.store.alert_state import AlertState
from monitor.service.store.sqlite import Store

disable_created_metrics()  # a counter's start time is not a series anyone graphs


class Counts(Protocol):
    """What the metrics read of a run's counts (:class:`monitor.assessment.day.RunCounts`)."""

    @property  # numpydoc ignore=RT01
    def downloaded(self) -> int: ...
    @property  # numpydoc ignore=RT01
    def bytes(self) -> int: ...
    @property  # numpydoc ignore=RT01
    def requests(self) -> int: ...


class Outcome(Protocol):
    """What the metrics read of a run (:class:`monitor.service.pipeline.RunOutcome`): its satellite and its
    counts. Typed so, the metrics and the pipeline (one floor) do not import each other."""

    @property  # numpydoc ignore=RT01
    def satellite(self) -> str: ...
    @property  # numpydoc ignore=RT01
    def counts(self) -> Counts: ...


class Health(Protocol):
    """What the metrics read of the daemon's health (:class:`monitor.service.health.Health`)."""

    def problems(self) -> list[str]: ...


OUTCOMES = tuple(s for s in RunStatus if s != RunStatus.RUNNING)  # final: a run row changes to one once


class _StoreCollector:
    """Reads the store at each scrape (a new connection each time: scrapes come on the server's thread)."""

    def __init__(
        self,
        open_store: Callable[[], Store],
        satellites: Iterable[str],
        health: Health,
        started: dt.datetime,
        spec_km: float,
    ) -> None:
        self.open_store = open_store
        self.satellites = list(satellites)
        self.spec_km = spec_km
        self.health = health
        self.started = started

    def collect(self) -> Iterator[Metric]:
        with self.open_store() as store:
            success = store.last_success()
            first = store.first_runs()
            counts = store.run_counts()
            outbox = store.outbox_sizes()
            firing = AlertState(store).firing()
            latest = {s: store.latest_day(s) for s in self.satellites}
            precision = {s: store.latest_precision(s) for s in self.satellites}
            fors = {s: store.day_result(s, d) for s, d in latest.items() if d is not None}
            stages = store.latest_stages()
        g = GaugeMetricFamily(
            "crisgeo_last_success_timestamp_seconds",
            "End of the latest successful run (Unix time), 0 before the first",
            labels=["satellite"],
        )
        since = GaugeMetricFamily(
            "crisgeo_watched_since_timestamp_seconds",
            "Start of the satellite's first run, or of this process before any run (Unix time)",
            labels=["satellite"],
        )
        for sat in self.satellites:
            g.add_metric([sat], success[sat].timestamp() if sat in success else 0.0)
            since.add_metric([sat], first.get(sat, self.started).timestamp())
        yield g
        yield since
        duration = GaugeMetricFamily(
            "crisgeo_run_duration_seconds",
            "Wall time of each stage of the latest run",
            labels=["satellite", "stage"],
        )
        for sat in self.satellites:
            for stage, secs in stages.get(sat, {}).items():
                duration.add_metric([sat, stage], secs)
        yield duration
        c = CounterMetricFamily(
            "crisgeo_runs", "Finished runs in the ledger by outcome", labels=["satellite", "outcome"]
        )
        running = GaugeMetricFamily("crisgeo_runs_in_progress", "Runs under way", labels=["satellite"])
        for sat in self.satellites:
            for outcome in OUTCOMES:
                c.add_metric([sat, outcome], counts.get((sat, outcome), 0))
            running.add_metric([sat], counts.get((sat, RunStatus.RUNNING), 0))
        yield c
        yield running
        g = GaugeMetricFamily(
            "crisgeo_outbox_points", "Time-series points waiting to be sent", labels=["target"]
        )
        for target, n in outbox.items():
            g.add_metric([target], n)
        yield g
        g = GaugeMetricFamily(
            "crisgeo_alerts_firing", "Alerts firing now", labels=["satellite", "rule", "severity"]
        )
        per: dict[tuple[str, str, str], int] = {}
        for a in firing:
            key = (a.satellite, a.rule, a.severity or "")
            per[key] = per.get(key, 0) + 1
        for key, n in sorted(per.items()):
            g.add_metric(list(key), n)
        yield g
        yield from self._offsets(latest, fors, self.spec_km)
        yield from self._precision(precision)
        yield GaugeMetricFamily(
            "crisgeo_healthy", "1 when /healthz is ok", value=0 if self.health.problems() else 1
        )

    @staticmethod
    def _precision(precision: dict[str, DayPrecision | None]) -> Iterator[Metric]:
        granules = GaugeMetricFamily(
            "crisgeo_day_granules_assessed", "CrIS granules the latest ok run assessed", labels=["satellite"]
        )
        sigma = GaugeMetricFamily(
            "crisgeo_day_sigma_radians",
            "Median per-FOR jackknife sigma (worse direction) the latest ok run reached",
            labels=["satellite"],
        )
        target = GaugeMetricFamily(
            "crisgeo_day_target_sigma_radians",
            "The precision target of the latest ok run (its scenes key, in radians)",
            labels=["satellite"],
        )
        stop = GaugeMetricFamily(
            "crisgeo_day_stop_info",
            "Why the latest ok run stopped assessing (1 on its reason)",
            labels=["satellite", "reason"],
        )
        for sat, p in precision.items():
            if p is None:
                continue
            granules.add_metric([sat], p.granules)
            if p.sigma_urad is not None:
                sigma.add_metric([sat], p.sigma_urad * URAD)
            if p.target_sigma_urad is not None:
                target.add_metric([sat], p.target_sigma_urad * URAD)
            for reason in DayStop:
                stop.add_metric([sat, reason.name.lower()], 1 if p.stop == reason else 0)
        yield from (granules, sigma, target, stop)

    @staticmethod
    def _offsets(
        latest: dict[str, dt.date | None], fors: dict[str, list[ForOffset]], spec_km: float
    ) -> Iterator[Metric]:
        day = GaugeMetricFamily(
            "crisgeo_latest_day_timestamp_seconds",
            "00:00 UTC of the latest assessed day",
            labels=["satellite"],
        )
        beyond = GaugeMetricFamily(
            "crisgeo_for_beyond_spec",
            "1 when the FOR's latest in-track or cross-track error is beyond the specification",
            labels=["satellite", "for"],
        )
        # the families the FOR's fields are published in, as their declaration says (ForOffset)
        families = {m.metric[0]: _gauge(m.metric[0]) for m in measures() if m.metric}
        ok = GaugeMetricFamily(
            "crisgeo_for_reliable",
            "1 when the FOR's latest offset carries no reliability flag",
            labels=["satellite", "for"],
        )
        for sat, d in latest.items():
            if d is None:
                continue
            day.add_metric([sat], dt.datetime.combine(d, dt.time(), dt.timezone.utc).timestamp())
            for f in fors[sat]:
                k = f"{f.for_index:02d}"
                for m in measures(type(f)):
                    v = getattr(f, m.name)
                    if m.metric is None or not math.isfinite(v):
                        continue
                    family, label = m.metric
                    gauge = families.setdefault(family, _gauge(family))
                    gauge.add_metric([sat, k, *([label] if family.label else [])], v * m.to_base_unit)
                beyond.add_metric([sat, k], 1 if f.spec_breaches(spec_km) else 0)
                ok.add_metric([sat, k], 1 if f.reliable else 0)
        yield from (day, *families.values(), beyond, ok)


def _gauge(family: Family) -> GaugeMetricFamily:
    """The gauge of a per-FOR family: labelled by satellite and FOR (and the family's own label)."""
    return GaugeMetricFamily(
        family.name, family.help, labels=["satellite", "for", *([family.label] if family.label else [])]
    )


class ServiceMetrics:
    """The daemon's registry: the store's view at each scrape plus this process's run figures.

    Parameters
    ----------
    open_store : callable
        Opens the store for a scrape.
    satellites : iterable of str
        The configured satellites.
    health : Health
        The daemon's jobs and scheduler heartbeat.
    version : str
        crisgeo's version (``crisgeo_build_info``).
    spec_km : float
        The specification, km (``alerts.spec_km``).
    """

    def __init__(
        self,
        open_store: Callable[[], Store],
        satellites: Iterable[str],
        health: Health,
        version: str,
        spec_km: float,
    ) -> None:
        self.registry = CollectorRegistry()
        self.registry.register(
            _StoreCollector(open_store, satellites, health, dt.datetime.now(dt.timezone.utc), spec_km)
        )
        for standard in (PROCESS_COLLECTOR, PLATFORM_COLLECTOR, GC_COLLECTOR):  # process_*, python_*
            self.registry.register(standard)
        self.granules = Counter(
            "crisgeo_downloaded_granules",
            "Files downloaded whole by this process",
            ["satellite"],
            registry=self.registry,
        )
        self.bytes = Counter(
            "crisgeo_downloaded_bytes",
            "Bytes downloaded by this process (whole files and ranges)",
            ["satellite"],
            registry=self.registry,
        )
        self.requests = Counter(
            "crisgeo_nodd_requests",
            "HTTP requests to NODD by this process (listings, downloads, ranges)",
            ["satellite"],
            registry=self.registry,
        )
        Gauge("crisgeo_build_info", "The running version", ["version"], registry=self.registry).labels(
            version
        ).set(1)
        for sat in satellites:
            self.granules.labels(sat)
            self.bytes.labels(sat)
            self.requests.labels(sat)

    def record(self, outcome: Outcome) -> None:
        """Take in a :class:`monitor.service.pipeline.RunOutcome`'s downloads.

        Parameters
        ----------
        outcome : Outcome
            A run's outcome (:class:`monitor.service.pipeline.RunOutcome`).
        """
        self.granules.labels(outcome.satellite).inc(outcome.counts.downloaded)
        self.bytes.labels(outcome.satellite).inc(outcome.counts.bytes)
        self.requests.labels(outcome.satellite).inc(outcome.counts.requests)
