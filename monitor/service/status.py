"""``crisgeo status`` as data: per satellite the last run, the latest per-FOR offsets and the alerts
firing (with the silence that quiets each); whether a daemon holds the state directory, and its next run;
the outbox; and the Nagios state of it all (0 OK, 1 WARNING, 2 CRITICAL, 3 UNKNOWN).

The state is what the alerts say, silenced or not: a silence quiets the notifications, as a Nagios
acknowledgement or an Alertmanager silence does, and is shown beside the state, never folded into it.
The Nagios line (:meth:`Status.nagios_line`) follows the plugin convention: ``STATE - reason | perfdata``.
On top of the alerts, the monitoring-plugins thresholds (:class:`Thresholds`: ranges on the worst error and
on the FORs beyond the specification, parsed by ``nagiosplugin.Range``) and staleness (no successful
assessment for ``stale_days``) raise the state; nothing lowers what an alert says.
"""

from __future__ import annotations

import datetime as dt
from dataclasses import asdict, dataclass
from enum import IntEnum

from nagiosplugin import Range

from monitor.config.model import Config
from monitor.core.result import DayPrecision, ForOffset, worst_for
from monitor.core.tables import BRIEF, for_table
from monitor.core.vocabulary import Rule, RunStatus, Severity
from monitor.history.records import Run, Silence, last_success
from monitor.service.lock import holder
from monitor.service.store.alert_state import AlertState
from monitor.service.store.sqlite import Store
from monitor.service.timetable import next_run


class NagiosState(IntEnum):
    """The Nagios plugin states; the value is the exit status."""

    OK = 0
    WARNING = 1
    CRITICAL = 2
    UNKNOWN = 3


@dataclass(frozen=True)
class Thresholds:
    """``crisgeo status -w/-c``: monitoring-plugins ranges (``10``: outside 0..10 alerts, ``~:10``,
    ``10:20``, ``@10:20``: inside alerts) on the worst error (km) and on the count of FORs beyond the
    specification, each for WARNING and CRITICAL (None: not checked); and the days without a successful
    assessment after which a satellite is WARNING."""

    warning_km: Range | None = None
    critical_km: Range | None = None
    warning_fors: Range | None = None
    critical_fors: Range | None = None
    stale_days: float = 2.0

    def state(self, worst_km: float | None, fors_beyond: int) -> NagiosState:
        """The state these ranges give the worst error and the FORs beyond the specification.

        Parameters
        ----------
        worst_km : float or None
            The worst error, km.
        fors_beyond : int
            FORs beyond the specification.

        Returns
        -------
        NagiosState
            The state the thresholds give.
        """
        checks = ((self.critical_km, worst_km, NagiosState.CRITICAL), (self.critical_fors, fors_beyond,
                  NagiosState.CRITICAL), (self.warning_km, worst_km, NagiosState.WARNING),
                  (self.warning_fors, fors_beyond, NagiosState.WARNING))  # fmt: skip
        for limit, value, state in checks:
            if limit is not None and value is not None and not limit.match(value):
                return state
        return NagiosState.OK

    def text(self, limit: Range | None) -> str:
        """A range as perfdata writes it (empty: none).

        Parameters
        ----------
        limit : Range or None
            A threshold.

        Returns
        -------
        str
            As perfdata writes it (empty: none).
        """
        return "" if limit is None else str(limit)


@dataclass(frozen=True)
class FiringAlert:
    """An alert firing now, and the silence in force over it (None: it notifies)."""

    rule: str
    severity: str
    summary: str
    started: str
    silence: Silence | None = None

    def silenced_text(self) -> str:
        """`` (silenced until ...: reason)``, or nothing.

        Returns
        -------
        str
            Until when and why it is silenced.
        """
        if self.silence is None:
            return ""
        why = f": {self.silence.reason}" if self.silence.reason else ""
        return f" (silenced until {self.silence.until}{why})"


@dataclass(frozen=True)
class SatelliteStatus:
    """One satellite: its last run, its latest assessed day and that day's FORs, its alerts firing."""

    satellite: str
    last_run: Run | None
    latest_day: dt.date | None
    fors: tuple[ForOffset, ...]
    alerts: tuple[FiringAlert, ...]
    spec_km: float
    precision: DayPrecision | None = None  # how far the latest ok run went, and why it stopped
    stale_since: dt.datetime | None = None  # no successful assessment since (UTC): past the stale limit

    @property
    def beyond_spec(self) -> tuple[ForOffset, ...]:  # numpydoc ignore=RT01
        """The latest day's FORs beyond the specification (the one rule of :mod:`monitor.core.result`)."""
        return tuple(f for f in self.fors if f.spec_breaches(self.spec_km))

    @property
    def worst_km(self) -> float | None:  # numpydoc ignore=RT01
        """The worst error of the latest day (:func:`monitor.core.result.worst_for`), km."""
        worst = worst_for(self.fors)
        return None if worst is None else worst.worst_km

    def reasons(self) -> list[str]:
        """What makes the state, one phrase each: the failed last run, each alert firing (silences
        named), or the latest day's standing when all is well.

        Returns
        -------
        list of str
            Why its state is not OK.
        """
        out = []
        if self.last_run is not None and self.last_run.status == RunStatus.FAILED:
            out.append(f"{self.satellite}: run of {self.last_run.day} failed: {self.last_run.reason or '?'}")
        if self.stale_since is not None:
            out.append(
                f"{self.satellite}: no successful assessment since {self.stale_since:%Y-%m-%d %H:%M} UTC"
            )
        for a in self.alerts:
            if a.rule == Rule.SPEC and self.beyond_spec:
                text = (
                    f"{self.satellite}: {len(self.beyond_spec)} FOR(s) beyond {self.spec_km:g} km "
                    f"(worst {self.worst_km:.2f} km)"
                )
            else:
                text = a.summary
            out.append(f"{text}{a.silenced_text()}")
        return out

    def perfdata(self, t: Thresholds) -> list[str]:
        """Nagios performance data: FORs beyond the specification and the worst error (km), with the
        warning and critical ranges in force.

        Parameters
        ----------
        t : Thresholds
            The thresholds.

        Returns
        -------
        list of str
            Nagios perfdata: FORs beyond the specification and the worst error.
        """
        if self.latest_day is None:
            return []
        out = [
            f"{self.satellite}_fors_beyond_spec={len(self.beyond_spec)};{t.text(t.warning_fors)};"
            f"{t.text(t.critical_fors)};0;{len(self.fors)}"
        ]
        if self.worst_km is not None:
            out.append(
                f"{self.satellite}_worst_km={self.worst_km:.3f};{t.text(t.warning_km)};{t.text(t.critical_km)};0"
            )
        return out


@dataclass(frozen=True)
class Status:
    """What ``crisgeo status`` shows: every chosen satellite, the daemon holding the state directory (its
    pid, None when none runs) and its next run (UTC), the outbox size, and the Nagios state."""

    state: NagiosState
    satellites: tuple[SatelliteStatus, ...]
    daemon_pid: int | None
    next_run_utc: dt.datetime | None
    outbox: int
    thresholds: Thresholds = Thresholds()

    def nagios_line(self) -> str:
        """``STATE - reasons | perfdata``: the first line a Nagios plugin prints.

        Returns
        -------
        str
            The plugin's first line: state, reason, perfdata.
        """
        reasons = [r for s in self.satellites for r in s.reasons()]
        t = self.thresholds
        reasons += [
            f"{s.satellite}: worst {s.worst_km:.2f} km, {len(s.beyond_spec)} FOR(s) beyond {s.spec_km:g} km "
            f"(thresholds: {state.name})"
            for s in self.satellites
            if (state := t.state(s.worst_km, len(s.beyond_spec))) != NagiosState.OK
            and s.worst_km is not None
            and not any(a.rule == Rule.SPEC for a in s.alerts)  # its reason names the worst already
        ]
        if not reasons:
            reasons = [
                f"{s.satellite}: {s.latest_day or 'no day yet'}"
                + (f", worst {s.worst_km:.2f} km" if s.worst_km is not None else "")
                for s in self.satellites
            ]
        perf = " ".join(p for s in self.satellites for p in s.perfdata(self.thresholds))
        return f"{self.state.name} - {'; '.join(reasons)}" + (f" | {perf}" if perf else "")

    def text(self) -> str:
        """What ``crisgeo status`` prints: the Nagios line first (state, reasons, perfdata), then per
        satellite its last run, its alerts (silences named) and its latest FORs, the daemon, the outbox.

        Returns
        -------
        str
            The human-readable status.
        """
        lines = [self.nagios_line()]
        for s in self.satellites:
            r = s.last_run
            lines.append(
                f"{s.satellite}: no run yet"
                if r is None
                else f"{s.satellite}: last run {r.day} {r.status} (finished {r.finished or '-'})"
                + (f": {r.reason}" if r.reason else "")
            )
            lines += [
                f"  {a.severity} {a.rule}: {a.summary} (since {a.started})" + a.silenced_text()
                for a in s.alerts
            ]
            if s.precision is not None:
                lines.append(f"  precision: {s.precision.text()}")
            if s.latest_day:
                lines.append(f"  latest results: {s.latest_day}")
                lines += for_table(list(s.fors), BRIEF, indent="  ")
        if self.next_run_utc is None:
            lines.append("daemon: not running on this state directory (no run scheduled)")
        else:
            lines.append(
                f"daemon: pid {self.daemon_pid}, next scheduled run {self.next_run_utc:%Y-%m-%d %H:%M} UTC"
            )
        lines.append(f"outbox: {self.outbox} point(s) waiting")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """The JSON of ``crisgeo status --json``.

        Returns
        -------
        dict
            ``crisgeo status --json``.
        """
        return {
            "state": self.state.name,
            "exit": int(self.state),
            "summary": self.nagios_line(),
            "satellites": {
                s.satellite: {
                    "last_run": None
                    if s.last_run is None
                    else {k: getattr(s.last_run, k) for k in ("day", "status", "finished", "reason")},
                    "latest_day": None if s.latest_day is None else s.latest_day.isoformat(),
                    "precision": None if s.precision is None else s.precision.to_dict(),
                    "fors": [f.to_dict() for f in s.fors],
                    "fors_beyond_spec": [f.for_index for f in s.beyond_spec],
                    "alerts": [
                        {
                            "rule": a.rule,
                            "severity": a.severity,
                            "summary": a.summary,
                            "started": a.started,
                            "silence": None if a.silence is None else asdict(a.silence),
                        }
                        for a in s.alerts
                    ],
                }
                for s in self.satellites
            },
            "daemon_pid": self.daemon_pid,
            "next_run_utc": None if self.next_run_utc is None else f"{self.next_run_utc:%Y-%m-%dT%H:%MZ}",
            "outbox": self.outbox,
        }


def status_report(
    cfg: Config,
    store: Store,
    satellites: list[str] | None = None,
    now: dt.datetime | None = None,
    thresholds: Thresholds | None = None,
) -> Status:
    """The :class:`Status` of *satellites* (default: the configured ones) at *now*, the *thresholds*
    (default: WARNING beyond the specification, stale after 2 days) over the alerts.

    Parameters
    ----------
    cfg : Config
        The configuration.
    store : Store
        The service's store.
    satellites : list of str, optional
        The satellites; the configured ones by default.
    now : datetime.datetime, optional
        Now, UTC.
    thresholds : Thresholds, optional
        WARNING beyond the specification, stale after 2 days, by default.

    Returns
    -------
    Status
        The status.
    """
    now = now or dt.datetime.now(dt.timezone.utc)
    t = thresholds or Thresholds(warning_km=Range(f"{cfg.alerts.spec_km:g}"))
    runs = {r.satellite: r for r in store.last_runs()}
    chosen = list(satellites or cfg.satellites)
    state = AlertState(store)
    firing = [a for a in state.firing() if a.satellite in chosen or a.satellite is None]
    sats = []
    for sat in chosen:
        day = store.latest_day(sat)
        alerts = tuple(
            FiringAlert(
                a.rule, a.severity or "", a.summary or "", a.started or "", state.silenced(a.rule, sat, now)
            )
            for a in firing
            if a.satellite == sat
        )
        sats.append(
            SatelliteStatus(
                sat,
                runs.get(sat),
                day,
                () if day is None else tuple(store.day_result(sat, day)),
                alerts,
                cfg.alerts.spec_km,
                store.latest_precision(sat),
                _stale_since(store, sat, now, t.stale_days),
            )
        )
    critical = any(a.severity == Severity.CRITICAL for a in firing) or any(
        s.last_run is not None and s.last_run.status == RunStatus.FAILED for s in sats
    )
    daemon = holder(cfg.state_dir, "daemon")
    # a recorded step (severity info) is shown, not a problem
    warned = any(a.severity != Severity.INFO for a in firing) or any(s.stale_since for s in sats)
    by_alerts = NagiosState.CRITICAL if critical else NagiosState.WARNING if warned else NagiosState.OK
    by_thresholds = [t.state(s.worst_km, len(s.beyond_spec)) for s in sats]
    return Status(
        max([by_alerts, *by_thresholds]),
        tuple(sats),
        daemon,
        None if daemon is None else next_run(cfg.schedule, now),
        store.outbox_size(),
        t,
    )


def _stale_since(store: Store, satellite: str, now: dt.datetime, days: float) -> dt.datetime | None:
    """When *satellite* was last assessed successfully (:func:`monitor.history.records.last_success`), if
    that is more than *days* before *now*; else None."""
    since = last_success(store.runs(satellite))
    return since if since is not None and (now - since).total_seconds() > days * 86400 else None
