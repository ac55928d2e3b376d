"""The long-running service: one daily job per satellite under APScheduler, run by systemd.

* BlockingScheduler in UTC; per-satellite cron job with coalesce, one instance at a time and a misfire
  grace of hours; a catch-up job at start redoes the missed days (bounded window).
* SIGTERM/SIGINT set a stop event that the run polls between steps and granules, then the scheduler
  shuts down; a run cut short is recorded as interrupted and redone at the next start.
* A single-instance lock (flock on the state directory) keeps a second copy from running.
* sd_notify READY/STATUS/WATCHDOG/STOPPING over $NOTIFY_SOCKET, when systemd provides one; the watchdog
  is fed only while :mod:`monitor.service.health` holds (every run within ``schedule.run_budget_min``, the
  scheduler's heartbeat recent), so a wedged run or a stalled scheduler ends in a restart.
* One HTTP endpoint (``http.listen``): /metrics, /healthz, /report/ (:mod:`monitor.service.endpoint`).
* A job that fails or is missed becomes an event in the store, which the alerting layer reads.
"""

from __future__ import annotations

import datetime as dt
import functools
import logging
import os
import signal
import socket
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from types import FrameType

from apscheduler.events import EVENT_JOB_ERROR, EVENT_JOB_MAX_INSTANCES, EVENT_JOB_MISSED, JobEvent
from apscheduler.schedulers.blocking import BlockingScheduler
from apscheduler.triggers.cron import CronTrigger

from alerts.engine import evaluate_and_deliver
from monitor.archive.configured import make_source
from monitor.config.file import load_config
from monitor.config.keys import ConfigError, parse_listen
from monitor.config.model import Config
from monitor.core import logcontext
from monitor.core.vocabulary import EventKind, RunStatus
from monitor.history.records import Attachment
from monitor.service import allocator
from monitor.service.endpoint import Endpoint
from monitor.service.health import Health
from monitor.service.lock import InstanceLock
from monitor.service.outputs.metrics import ServiceMetrics
from monitor.service.outputs.timeseries import Drained, drain_outbox
from monitor.service.pipeline import RunOutcome, days_to_run, run_day
from monitor.service.store.sqlite import Store
from monitor.version import __version__

LOG = logging.getLogger(__name__)
UTC = dt.timezone.utc
HEARTBEAT_S = 30.0  # the scheduler's heartbeat job runs this often
STALL_S = 300.0  # ... and the scheduler counts as stalled when it has not run for this long


def sd_notify(message: str) -> bool:
    """Send *message* (e.g. ``READY=1``) to systemd's notify socket; False when not under systemd.

    Parameters
    ----------
    message : str
        ``READY=1``, ``STATUS=...``, ``WATCHDOG=1``, ``STOPPING=1``.

    Returns
    -------
    bool
        Whether it was sent (False outside systemd).
    """
    addr = os.environ.get("NOTIFY_SOCKET")
    if not addr:
        return False
    if addr.startswith("@"):
        addr = "\0" + addr[1:]
    try:
        with socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM) as s:
            s.connect(addr)
            # never block: a notify socket nobody reads (a wedged systemd, a test) must not stop the
            # daemon, even inside the SIGTERM handler; the message is dropped instead
            s.send(message.encode(), socket.MSG_DONTWAIT)
        return True
    except OSError as exc:
        log = LOG.debug if isinstance(exc, BlockingIOError) else LOG.warning
        log("sd_notify %s not delivered: %s", message.split("=", 1)[0], exc)
        return False


class Service:
    """Runs satellite-days for a configuration; the daemon adds the scheduler and signals.

    Parameters
    ----------
    cfg : Config
        The configuration.
    progress : callable, optional
        Called after each granule assessed.
    """

    def __init__(self, cfg: Config, progress: Callable[[object], None] | None = None) -> None:
        self.cfg = cfg
        self.stop_event = threading.Event()
        self.stopped_by: int | None = None  # the signal that asked for the stop (the exit status is 128 + it)
        self.progress = progress
        self.source = make_source(cfg)
        self.scheduler: BlockingScheduler | None = None
        self.health = Health(STALL_S)
        self.metrics: ServiceMetrics | None = None  # while the daemon serves /metrics

    def store(self) -> Store:
        """A new connection to the configured store (close it, or use it in ``with``).

        Returns
        -------
        Store
            A new connection.
        """
        return Store(self.cfg.store.path)

    def run(self, satellite: str, day: dt.date, today: dt.date | None = None) -> RunOutcome:
        """Run one satellite-day (health-tracked) as of *today* (default: the date now, UTC), then evaluate
        the alerts and regenerate the report.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.
        today : datetime.date, optional
            Today, UTC, for the no-data horizon.

        Returns
        -------
        RunOutcome
            The day's outcome, recorded.
        """
        today = today or dt.datetime.now(UTC).date()
        try:
            with self.store() as store, logcontext.context(satellite=satellite, day=day.isoformat()):
                LOG.info("run %s %s", satellite, day)
                sd_notify(f"STATUS=assessing {satellite} {day}")
                with self.health.job(f"run {satellite} {day}", self.cfg.schedule.run_budget_min * 60):
                    out = run_day(
                        self.cfg,
                        store,
                        self.source,
                        satellite,
                        day,
                        today,
                        self.stop_event.is_set,
                        self.progress,
                    )
                level = {RunStatus.FAILED: logging.ERROR, RunStatus.INTERRUPTED: logging.WARNING}
                LOG.log(level.get(out.status, logging.INFO), "%s", out.summary())
                if self.metrics is not None:
                    self.metrics.record(out)
                self._after_run(store)
                return out
        finally:
            # after the report and the alerts too: what they freed (their share grows with the history
            # they plot) would otherwise stay with the daemon until the next day
            allocator.release_freed_memory()

    def _after_run(self, store: Store) -> None:
        """After every run: evaluate the alert rules and deliver what is queued (the e-mails attach the
        trend plot), then regenerate the report (it shows the alerts)."""
        self.check_alerts(store, report=not self.stop_event.is_set())  # stopping: the next run rewrites it

    def regenerate_report(self, store: Store) -> None:
        """Rewrite the HTML report into ``report_dir``; a report problem never stops the service.

        Parameters
        ----------
        store : Store
            The service's store.
        """
        if not self.cfg.report_dir:
            return
        from monitor.service.outputs.report.html import (  # matplotlib: when first needed
            build_report,
            options_from_config,
        )

        try:
            build_report(store, self.cfg.report_dir, options_from_config(self.cfg))
        except Exception:  # noqa: BLE001 - matplotlib, disk or data surprises are logged, not fatal
            LOG.exception("report: could not regenerate %s", self.cfg.report_dir)

    def trend_attachment(self, store: Store, satellite: str) -> tuple[Attachment, ...]:
        """What an alert message of *satellite* attaches: the report's trend plot, drawn from the store
        (nothing when the service writes no report, or when the plot cannot be drawn: the message goes
        without it).

        Parameters
        ----------
        store : Store
            The service's store.
        satellite : str
            The satellite's short name.

        Returns
        -------
        tuple of Attachment
            The plot, or nothing.
        """
        if not self.cfg.report_dir:
            return ()
        from monitor.service.outputs.report.html import options_from_config, trend_attachment

        try:
            return trend_attachment(store, satellite, options_from_config(self.cfg))
        except Exception:  # noqa: BLE001 - a plot never holds back an alert
            LOG.exception(
                "alerts: could not draw the trend plot of %s; the message goes without it", satellite
            )
            return ()

    def check_alerts(self, store: Store | None = None, report: bool = False) -> None:
        """Evaluate the alert rules for every satellite and deliver the queue (then regenerate the report,
        when *report*); a broken channel never stops the service.

        Parameters
        ----------
        store : Store, optional
            The store; the service's own by default.
        report : bool, optional
            Regenerate the report after.
        """

        own = store is None
        store = store or self.store()
        try:
            counts = evaluate_and_deliver(
                store,
                self.cfg.alerts,
                self.cfg.satellites,
                attach=functools.partial(self.trend_attachment, store),
            )
            if counts.queued or counts.sent or counts.failed:
                LOG.info("alerts: %s", counts.text())
            if report:
                self.regenerate_report(store)
        finally:
            if own:  # the hourly timer: hand back what the evaluation freed
                store.close()
                allocator.release_freed_memory()

    def drain_outbox(self) -> dict[str, Drained]:
        """Send the time-series points waiting in the outbox (after an outage they need not wait for the
        next daily run).

        Returns
        -------
        dict of str to Drained
            Per target, the points sent and left.
        """

        with self.store() as store:
            report = drain_outbox(store, self.cfg.store.publish)
            if any(d.sent for d in report.values()):
                LOG.info(
                    "outbox: %s", "; ".join(f"{t}: {d.sent} sent, {d.left} left" for t, d in report.items())
                )
            return report

    def recover(self) -> None:
        """Mark runs left 'running' by a killed process as interrupted (call with the instance lock held)."""
        with self.store() as store:
            n = store.interrupt_stale_runs()
            if n:
                LOG.warning("%d run(s) were cut short by a previous process; their days will be redone", n)

    def handle_signals(self) -> None:
        """SIGTERM and SIGINT request a clean stop between steps."""
        for sig in (signal.SIGTERM, signal.SIGINT):
            signal.signal(sig, self._on_signal)

    def catch_up(self, satellite: str, today: dt.date | None = None) -> Iterator[RunOutcome]:
        """Run the days of the catch-up window that have no completed run, oldest first, yielding each
        outcome as its day ends (the daemon keeps none: a 90-day catch-up holds no 90 results).

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        today : datetime.date, optional
            Today, UTC.

        Returns
        -------
        iterator of RunOutcome
            Each missed day's outcome, oldest first.
        """
        today = today or dt.datetime.now(UTC).date()
        with self.store() as store:
            days = days_to_run(store, satellite, self.cfg.schedule, today)
        for day in days:
            if self.stop_event.is_set():
                break
            yield self.run(satellite, day, today)

    def daily_job(self, satellite: str) -> None:
        """The scheduled job of *satellite*: the days of its catch-up window.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        """
        for _ in self.catch_up(satellite):
            pass

    def run_once(self, satellites: Iterable[str], day: dt.date | None = None) -> list[RunOutcome]:
        """``crisgeo run``: under the instance lock, recover what a killed process left, then per satellite
        the given *day* or the days of the catch-up window; the outcomes. :class:`AlreadyRunning` when the
        daemon (or another run) holds the state directory.

        Parameters
        ----------
        satellites : iterable of str
            The satellites.
        day : datetime.date, optional
            One day; else the missed days.

        Returns
        -------
        list of RunOutcome
            The outcomes.
        """
        with InstanceLock(self.cfg.state_dir, "run"):
            self.recover()
            outcomes: list[RunOutcome] = []
            for sat in satellites:
                if self.stop_event.is_set():
                    break
                outcomes += [self.run(sat, day)] if day else self.catch_up(sat)
            return outcomes

    # -- daemon
    def add_jobs(self, scheduler: BlockingScheduler) -> None:
        """The daemon's jobs: per satellite the daily run (catching up at start), the hourly alert
        evaluation, and (with publishing) the outbox timer.

        Parameters
        ----------
        scheduler : BlockingScheduler
            APScheduler's scheduler.
        """

        sch = self.cfg.schedule
        now = dt.datetime.now(UTC)
        for sat in self.cfg.satellites:
            trigger = CronTrigger(hour=sch.time_utc.hour, minute=sch.time_utc.minute, timezone=UTC)
            scheduler.add_job(
                self.daily_job, trigger, args=[sat], id=f"daily-{sat}", name=f"daily {sat}", next_run_time=now
            )  # catch up at start, then daily
        scheduler.add_job(self.check_alerts, "interval", hours=1, id="alerts", name="alert timer")
        scheduler.add_job(
            self.health.beat,
            "interval",
            seconds=HEARTBEAT_S,
            id="heartbeat",
            name="heartbeat",
            next_run_time=now,
        )
        if self.cfg.store.publish:
            scheduler.add_job(
                self.drain_outbox,
                "interval",
                minutes=self.cfg.store.drain_minutes,
                id="outbox",
                name="outbox timer",
            )
        scheduler.add_listener(self._job_event, EVENT_JOB_ERROR | EVENT_JOB_MISSED | EVENT_JOB_MAX_INSTANCES)

    def start_endpoint(self, listen: str) -> Endpoint | None:
        """Serve /metrics, /healthz and /report/ on *listen* (``HOST:PORT``; ``off``: nothing).

        Parameters
        ----------
        listen : str
            ``HOST:PORT``, or ``off``.

        Returns
        -------
        Endpoint or None
            The endpoint started; None for ``off``.
        """
        if listen == "off":
            return None

        self.metrics = ServiceMetrics(
            self.store, self.cfg.satellites, self.health, __version__, self.cfg.alerts.spec_km
        )
        report = self.cfg.report_dir if self.cfg.report_dir else None
        return Endpoint(*parse_listen(listen), self.metrics, self.health, report).start()

    def daemon(self, listen: str | None = None) -> None:
        """Run the scheduler until SIGTERM/SIGINT; *listen* overrides ``http.listen``.

        Parameters
        ----------
        listen : str, optional
            ``HOST:PORT`` overriding ``http.listen``.
        """
        sch = self.cfg.schedule
        with InstanceLock(self.cfg.state_dir, "daemon"):
            endpoint = self.start_endpoint(listen or self.cfg.http.listen)
            self.recover()
            self.scheduler = BlockingScheduler(
                timezone=UTC,
                job_defaults={
                    "coalesce": True,
                    "max_instances": 1,
                    "misfire_grace_time": int(sch.misfire_grace_hours * 3600),
                },
            )
            self.add_jobs(self.scheduler)
            self.handle_signals()
            signal.signal(signal.SIGHUP, self._on_reload)  # systemctl reload: ExecReload sends it
            watchdog = self._start_watchdog()
            sd_notify("READY=1")
            sd_notify("STATUS=scheduled daily at " + sch.time_utc.strftime("%H:%M UTC"))
            LOG.info(
                "crisgeo daemon started for %s; daily at %s UTC",
                ", ".join(self.cfg.satellites),
                sch.time_utc.strftime("%H:%M"),
            )
            try:
                self.scheduler.start()
            finally:
                self.stop_event.set()
                if watchdog is not None:
                    watchdog.join(timeout=5)
                if endpoint is not None:
                    endpoint.stop()
                LOG.info("crisgeo daemon stopped")

    def reload(self) -> bool:
        """Read the configuration file again and put it in force: the scheduled jobs and the source follow
        it, a day under way finishes with the one it began with. A file that does not load, or that changes
        what only a restart can (``state_dir``, ``store.sqlite``, ``http.listen``), leaves the configuration
        in force, and the log says why.

        Returns
        -------
        bool
            Whether the new configuration is in force.
        """
        path = self.cfg.path
        if path is None:
            LOG.warning("reload: the configuration was not read from a file; nothing to reload")
            return False
        try:
            new = load_config(path)
        except (ConfigError, OSError) as exc:
            LOG.error("reload: %s; the configuration in force is kept", exc)
            return False
        fixed = [
            key
            for key, old_value, new_value in (
                ("state_dir", self.cfg.state_dir, new.state_dir),
                ("store.sqlite", self.cfg.store.sqlite, new.store.sqlite),
                ("http.listen", self.cfg.http.listen, new.http.listen),
            )
            if old_value != new_value
        ]
        if fixed:
            LOG.error(
                "reload: %s changed, which only a restart applies (systemctl restart crisgeo); the "
                "configuration in force is kept",
                ", ".join(fixed),
            )
            return False
        self.cfg, self.source = new, make_source(new)
        if self.scheduler is not None:
            self.scheduler.remove_all_jobs()
            self.add_jobs(self.scheduler)
        LOG.info(
            "reload: %s in force (%s; daily at %s UTC)",
            path,
            ", ".join(new.satellites),
            new.schedule.time_utc.strftime("%H:%M"),
        )
        return True

    def _on_reload(self, signum: int, frame: FrameType | None) -> None:
        sd_notify(f"RELOADING=1\nMONOTONIC_USEC={time.monotonic_ns() // 1000}")
        self.reload()
        sd_notify("READY=1")

    def _on_signal(self, signum: int, frame: FrameType | None) -> None:
        LOG.info("signal %d: stopping after the current step", signum)
        sd_notify("STOPPING=1")
        self.stopped_by = signum
        self.stop_event.set()
        if self.scheduler is not None and self.scheduler.running:  # a second signal finds it stopped
            self.scheduler.shutdown(wait=False)

    def _job_event(self, event: JobEvent) -> None:
        kind = {EVENT_JOB_ERROR: EventKind.JOB_ERROR, EVENT_JOB_MISSED: EventKind.JOB_MISSED}.get(
            event.code, EventKind.JOB_SKIPPED
        )
        # an error or a miss is a JobExecutionEvent (one run time); a skip (max instances) a
        # JobSubmissionEvent (its run times)
        when = getattr(event, "scheduled_run_times", None) or [getattr(event, "scheduled_run_time", None)]
        detail = {
            "job": event.job_id,
            "error": str(getattr(event, "exception", None) or kind.value),
            "scheduled": ", ".join(map(str, when)),
        }
        LOG.error("scheduler: %s: %s (scheduled %s)", detail["job"], detail["error"], detail["scheduled"])
        with self.store() as store:
            store.add_event(kind, event.job_id.split("-", 1)[-1], detail)
            self.check_alerts(store)

    def _start_watchdog(self) -> threading.Thread | None:
        usec = os.environ.get("WATCHDOG_USEC")
        if not usec:
            return None
        interval = int(usec) / 1e6 / 2

        def ping() -> None:
            reported: set[str] = (
                set()
            )  # what is wrong, by source (a job, the scheduler): said once, not every ping
            while not self.stop_event.wait(interval):
                sched = self.scheduler
                problems = (
                    self.health.problems()
                    if sched is not None and sched.running
                    else ["scheduler: not running"]
                )
                sources = {p.split(":", 1)[0] for p in problems}
                if not problems:
                    if reported:
                        LOG.info("healthy again; the watchdog is fed")
                    sd_notify("WATCHDOG=1")
                elif sources != reported:
                    LOG.error("unhealthy, the watchdog is no longer fed: %s", "; ".join(problems))
                    sd_notify("STATUS=unhealthy: " + "; ".join(problems)[:200])
                reported = sources

        t = threading.Thread(target=ping, name="watchdog", daemon=True)
        t.start()
        return t
