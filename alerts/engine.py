"""Evaluate the rules, update alert state, queue one message per satellite, deliver the queue.

Lifecycle (Alertmanager's conventions): an alert is notified when it starts firing, repeated while it
fires (every ``repeat_hours``), and notified when it resolves. Silenced alerts keep their state but
send nothing. Everything a run decides is committed before any channel is tried.

The engine reads the store as a :class:`~monitor.history.records.History` and writes to it through its
:class:`~monitor.history.records.AlertBook`; what a message attaches (the trend plot) is handed to it as
data by whoever calls it (:data:`Attach`), so the alerts know nothing of the report.
"""

from __future__ import annotations

import datetime as dt
import html
import logging
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from alerts.alertmanager import post_state
from alerts.band_rules import BAND_WATCHES, attribute_bands, radiometry_finding
from alerts.channels import Channel, Permanent, Transient, make_channels
from alerts.rules import (
    CALIBRATION,
    GEOLOCATION,
    Finding,
    failure_finding,
    jump_findings,
    processing_change_findings,
    spec_finding,
    stale_finding,
    watched_series,
)
from alerts.steps import replay_reach
from monitor.config.alert_settings import AlertSettings
from monitor.core.tables import Column, text_table
from monitor.core.vocabulary import AlertStatus, DeliveryStatus, Notice, Severity
from monitor.history.changes import all_changes
from monitor.history.records import Alert, AlertBook, AlertStore, Attachment, History, Message, Silence

LOG = logging.getLogger(__name__)
UTC = dt.timezone.utc
Attach = Callable[[str], Sequence[Attachment]]
"""What a satellite's message attaches, asked for only when a message is built (e-mail attaches it)."""
Notified = tuple[Notice, Finding]  # a finding and why it is sent now (firing, repeat, resolved)


def findings_for(
    store: AlertStore, satellite: str, settings: AlertSettings, now: dt.datetime
) -> list[Finding]:
    """Every rule's findings for *satellite* at *now*.

    Parameters
    ----------
    store : AlertStore
        The store's records (the jump rule keeps its noise fits in it).
    satellite : str
        The satellite's short name.
    settings : AlertSettings
        The ``alerts`` section.
    now : datetime.datetime
        Now, UTC.

    Returns
    -------
    list of Finding
        The findings.
    """
    s = settings
    out = [
        f
        for f in (
            spec_finding(store, satellite, s),
            radiometry_finding(store, satellite, s),
            stale_finding(store, satellite, s, now),
            failure_finding(store, satellite),
        )
        if f is not None
    ]
    latest = store.latest_day(satellite)
    if latest is not None:
        # the changes the jump rule's replay can meet (alerts.steps.replay_reach), however long the history
        reach = dt.timedelta(replay_reach(GEOLOCATION.rules(s)) + 1)
        changes = all_changes(store, satellite, settings.events_file, since=latest - reach)
        geolocation = jump_findings(store, satellite, changes, s)
        out += geolocation + jump_findings(store, satellite, changes, s, CALIBRATION)
        recent = latest - reach
        measured = {
            w.band for w in BAND_WATCHES if np.isfinite(watched_series(store, satellite, w, recent)[1]).any()
        }
        bands = [
            f
            for w in BAND_WATCHES
            if w.band in measured
            for f in jump_findings(store, satellite, changes, s, w)
        ]
        attribute_bands(bands, geolocation, measured, s)
        out += bands
    out += processing_change_findings(store, satellite, s, latest or now.date())
    return out


def _trend(store: History, satellite: str, days: int = 7) -> list[str]:
    latest = store.latest_day(satellite)
    if latest is None:
        return []
    # the last *days* assessed days, looked for over ten times as many calendar days
    series = store.series(satellite, since=latest - dt.timedelta(10 * days), fields=("total_km",))
    total = series.values["total_km"]
    lines = []
    for i in [i for i in range(len(series)) if np.isfinite(total[i]).any()][-days:]:
        k = int(np.nanargmax(total[i]))
        lines.append(f"{series.days[i]}: worst FOR {k + 1} total {total[i, k]:.2f} km")
    return lines


def build_message(
    store: History,
    satellite: str,
    items: Sequence[Notified],
    settings: AlertSettings,
    attachments: Sequence[Attachment] = (),
) -> Message:
    """One message for a satellite: every alert that started, repeats or resolved, with evidence.

    Parameters
    ----------
    store : History
        The store's records.
    satellite : str
        The satellite's short name.
    items : sequence of (Notice, Finding)
        The alerts that started, repeat or resolved, with their notices.
    settings : AlertSettings
        The ``alerts`` section.
    attachments : sequence of Attachment, optional
        What an e-mail attaches.

    Returns
    -------
    Message
        The message every channel sends.
    """
    counts: dict[str, int] = {}
    for kind, _ in items:
        counts[kind] = counts.get(kind, 0) + 1
    head = ", ".join(f"{n} {k}" for k, n in counts.items())
    worst = (
        Severity.CRITICAL
        if any(f.severity == Severity.CRITICAL and k != Notice.RESOLVED for k, f in items)
        else (Notice.RESOLVED if all(k == Notice.RESOLVED for k, _ in items) else Severity.WARNING)
    )
    subject = f"{settings.subject_prefix} {satellite} {worst.upper()}: {head} - " + "; ".join(
        f.rule for _, f in items
    )
    blocks, text = [], []
    for kind, f in items:
        title = f"{kind.upper()} {f.rule} ({f.severity if kind != Notice.RESOLVED else kind}): {f.summary}"
        text += [title] + [f"  {line}" for line in f.lines] + [""]
        blocks.append("*" + _slack_escape(title) + "*\n" + "\n".join(_slack_escape(x) for x in f.lines[:25]))
    day = store.latest_day(satellite)
    if day is not None:
        grans = store.granules(satellite, day)
        text.append(
            f"assessment of {day}: {len(grans)} granule pair(s): "
            + ", ".join(g.granule_id for g in grans[:14])
        )
    trend = _trend(store, satellite)
    if trend:
        text += ["trend (last days):"] + [f"  {t}" for t in trend]
    where = []
    if settings.links.report_url:
        where.append(f"report: {settings.links.report_url.rstrip('/')}/{satellite}/")
    elif settings.links.report_dir:
        where.append(
            f"report: {settings.links.report_dir / satellite / 'index.html'} (on the server; set report_url)"
        )
    if settings.links.dashboard_url:
        where.append(f"dashboard: {settings.links.dashboard_url}")
    text += where
    if trend or where:
        blocks.append(_slack_escape("\n".join(["trend:"] + trend + where)))
    body = "\n".join(text)
    return Message(
        subject,
        body,
        f"<html><body><h3>{html.escape(subject)}</h3><pre>{html.escape(body)}</pre></body></html>",
        tuple(blocks),
        tuple(attachments),
    )


def _slack_escape(s: str) -> str:
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def evaluate(
    store: AlertStore,
    settings: AlertSettings,
    satellites: Iterable[str],
    now: dt.datetime | None = None,
    attach: Attach | None = None,
) -> list[tuple[str, Message]]:
    """Update alert state from the rules and queue the messages; returns [(satellite, message)] queued.

    Parameters
    ----------
    store : AlertStore
        The store's records, and the alerts' book in it.
    settings : AlertSettings
        The ``alerts`` section.
    satellites : iterable of str
        The satellites.
    now : datetime.datetime, optional
        Now, UTC; the clock's by default.
    attach : callable, optional
        What a satellite's message attaches (:data:`Attach`); nothing by default.

    Returns
    -------
    list of (str, Message)
        (satellite, message) queued.
    """
    now = now or dt.datetime.now(UTC)
    state = store.alert_state()
    repeat = dt.timedelta(hours=settings.repeat_hours)
    queued = []
    for sat in satellites:
        found = findings_for(store, sat, settings, now)
        items: list[Notified] = []
        with store.transaction():
            for f in found:
                prev = state.get(f.alert_id)
                quiet = state.silenced(f.rule, sat, now) is not None
                kind: Notice | None
                if (
                    prev is None
                    or prev.status != AlertStatus.FIRING
                    or (prev.severity == Severity.INFO and f.severity != Severity.INFO)  # grew: paged now
                ):
                    kind = Notice.FIRING
                elif (
                    prev.last_notified is None
                    or now - dt.datetime.fromisoformat(prev.last_notified) >= repeat
                ):
                    kind = Notice.REPEAT
                else:
                    kind = None
                # a finding of severity info (a step below the practical size) is recorded, never sent
                notify = kind is not None and not quiet and f.severity != Severity.INFO
                state.upsert(f, now, notified=notify)
                if notify and kind is not None:
                    items.append((kind, f))
            current = {f.alert_id for f in found}
            for prev in state.firing(sat):
                if prev.alert_id not in current:
                    state.resolve(prev.alert_id, now)
                    if state.silenced(prev.rule, sat, now) is None and prev.severity != Severity.INFO:
                        items.append(
                            (
                                Notice.RESOLVED,
                                Finding(
                                    prev.rule,
                                    sat,
                                    prev.severity or Severity.WARNING,
                                    f"resolved: {prev.summary}",
                                    [],
                                    prev.grp or "",
                                ),
                            )
                        )
            for kind, f in items:  # one line per alert, its name a field of its own (the journal's ALERT)
                LOG.info(
                    "%s %s (%s): %s",
                    str(kind).upper(),
                    f.alert_id,
                    f.severity,
                    f.summary,
                    extra={"alert": f.alert_id},
                )
            if items:
                msg = build_message(store, sat, items, settings, attach(sat) if attach else ())
                for channel in settings.channels:
                    state.enqueue(channel, sat, msg, now)
                queued.append((sat, msg))
    return queued


@dataclass
class DeliveryCounts:
    """What one evaluation and delivery did: messages queued; deliveries sent, postponed to a retry, and
    failed for good."""

    queued: int = 0
    sent: int = 0
    retry: int = 0
    failed: int = 0
    held: tuple[str, ...] = ()  # alerts firing that were not sent again: notified within repeat_hours

    def text(self) -> str:
        """``queued 1, sent 3, to retry 0, failed 0``, and the alerts held back by the repeat interval.

        Returns
        -------
        str
            The line.
        """
        line = f"queued {self.queued}, sent {self.sent}, to retry {self.retry}, failed {self.failed}"
        if self.held:
            line += "; not sent again within the repeat interval (alerts.repeat_hours): " + "; ".join(
                self.held
            )
        return line


def deliver(
    store: AlertBook,
    settings: AlertSettings,
    now: dt.datetime | None = None,
    channels: dict[str, Channel] | None = None,
) -> DeliveryCounts:
    """Try every due delivery once; the counts by outcome. Never raises for a channel.

    Parameters
    ----------
    store : History
        The store's records.
    settings : AlertSettings
        The ``alerts`` section.
    now : datetime.datetime, optional
        Now, UTC; the clock's by default.
    channels : dict, optional
        {name: channel}; those the settings configure by default.

    Returns
    -------
    DeliveryCounts
        The counts by outcome.
    """
    now = now or dt.datetime.now(UTC)
    state = store.alert_state()
    channels = channels if channels is not None else make_channels(settings)
    counts = DeliveryCounts()
    for d in state.due(now):
        if not state.claim(d.id, now):
            continue  # another process is sending it
        ch = channels.get(d.channel)
        if ch is None:
            state.mark(d.id, DeliveryStatus.FAILED, now, f"channel {d.channel} is no longer configured")
            counts.failed += 1
            continue
        try:
            ch.send(d.body)
        except Transient as exc:
            wait = max(exc.retry_after_s, 60.0 * min(2**d.attempts, 60))
            state.mark(d.id, DeliveryStatus.PENDING, now, str(exc), retry_after_s=wait)
            LOG.warning("alert delivery via %s postponed: %s", d.channel, exc)
            counts.retry += 1
        except Permanent as exc:
            state.mark(d.id, DeliveryStatus.FAILED, now, str(exc))
            LOG.error("alert delivery via %s failed (configuration error): %s", d.channel, exc)
            counts.failed += 1
        else:
            state.mark(d.id, DeliveryStatus.SENT, now)
            counts.sent += 1
    return counts


def evaluate_and_deliver(
    store: AlertStore,
    settings: AlertSettings,
    satellites: Iterable[str],
    now: dt.datetime | None = None,
    attach: Attach | None = None,
) -> DeliveryCounts:
    """Evaluate the rules, queue, deliver; the counts (queued, sent, to retry, failed).

    Parameters
    ----------
    store : AlertStore
        The store's records, and the alerts' book in it.
    settings : AlertSettings
        The ``alerts`` section.
    satellites : iterable of str
        The satellites.
    now : datetime.datetime, optional
        Now, UTC; the clock's by default.
    attach : callable, optional
        What a satellite's message attaches (:data:`Attach`); nothing by default.

    Returns
    -------
    DeliveryCounts
        The counts.
    """
    now = now or dt.datetime.now(UTC)
    queued = evaluate(store, settings, satellites, now, attach)
    counts = deliver(store, settings, now)
    counts.queued = len(queued)
    counts.held = held_back(store, settings, now)
    post_state(store, settings, now)
    return counts


def held_back(store: AlertBook, settings: AlertSettings, now: dt.datetime) -> tuple[str, ...]:
    """The alerts firing, sent before *now* and not silenced, that the repeat interval keeps from being sent
    again at *now*: each as ``id (sent T, again from T')``.

    Parameters
    ----------
    store : AlertBook
        The alerts' book in the store.
    settings : AlertSettings
        The ``alerts`` section.
    now : datetime.datetime
        Now, UTC.

    Returns
    -------
    tuple of str
        ``id (sent T, again from T')`` each.
    """
    state = store.alert_state()
    repeat = dt.timedelta(hours=settings.repeat_hours)
    out = []
    for a in state.firing():
        if a.severity == Severity.INFO or a.last_notified is None or state.silenced(a.rule, a.satellite, now):
            continue
        sent = dt.datetime.fromisoformat(a.last_notified)
        if sent < now < sent + repeat:
            out.append(
                f"{a.alert_id} (sent {sent:%Y-%m-%d %H:%M}, again from {sent + repeat:%Y-%m-%d %H:%M} UTC)"
            )
    return tuple(out)


@dataclass(frozen=True)
class AlertView:
    """One alert as ``crisgeo alerts list`` shows it: *shown* is its status, or ``silenced`` while a silence
    quiets it."""

    shown: str
    alert: Alert

    def to_dict(self) -> dict:
        a = self.alert
        return {
            "status": self.shown,
            "severity": a.severity,
            "rule": a.rule,
            "satellite": a.satellite,
            "alert_id": a.alert_id,
            "fingerprint": a.alert_id,  # the name before 1.1, kept for scripts (Alertmanager's word for it)
            "started": a.started,
            "resolved": a.resolved,
            "summary": a.summary,
            "lines": a.lines,
        }


@dataclass(frozen=True)
class AlertsView:
    """What ``crisgeo alerts list`` shows: the alerts (firing, silenced, resolved in the last 7 days), the
    silences in force and the number of messages waiting for delivery."""

    alerts: tuple[AlertView, ...]
    silences: tuple[Silence, ...]
    pending_deliveries: int

    def to_dict(self) -> dict:
        """The JSON of ``crisgeo alerts list --json``.

        Returns
        -------
        dict
            The JSON.
        """
        return {
            "alerts": [a.to_dict() for a in self.alerts],
            "silences": [
                {"id": s.id, "rule": s.rule, "satellite": s.satellite, "until": s.until, "reason": s.reason}
                for s in self.silences
            ],
            "pending_deliveries": self.pending_deliveries,
        }

    def text(self) -> str:
        """The text of ``crisgeo alerts list``: the alerts' table, the silences, the deliveries waiting.

        Returns
        -------
        str
            The text.
        """
        if not (self.alerts or self.pending_deliveries or self.silences):
            return "no alerts"
        lines = text_table(self.alerts, ALERT_COLUMNS) if self.alerts else []
        lines += [
            f"silence {s.id:<3} rule={s.rule or '*'} satellite={s.satellite or '*'} until {s.until}: "
            f"{s.reason}"
            for s in self.silences
        ]
        lines.append(f"{self.pending_deliveries} message(s) waiting for delivery")
        return "\n".join(lines)


ALERT_COLUMNS = (
    Column("status", "shown", "", 9, align="<"),
    Column("severity", lambda v: v.alert.severity or "", "", 8, align="<"),
    Column("alert", "alert.alert_id", "", 28, align="<"),
    Column("since", lambda v: v.alert.started or "", "", 25, align="<"),
    Column("resolved", lambda v: v.alert.resolved or "", "", 25, align="<"),
    Column("summary", lambda v: v.alert.summary or "", "", 0, align="<"),
)


def alerts_view(store: AlertBook, now: dt.datetime) -> AlertsView:
    """The :class:`AlertsView` of the store at *now*.

    Parameters
    ----------
    store : AlertBook
        The alerts' book in the store.
    now : datetime.datetime
        Now, UTC.

    Returns
    -------
    AlertsView
        The view.
    """
    state = store.alert_state()
    shown = []
    for r in state.all():
        if (
            r.status == AlertStatus.RESOLVED
            and r.resolved
            and now - dt.datetime.fromisoformat(r.resolved) > dt.timedelta(days=7)
        ):
            continue
        quiet = state.silenced(r.rule, r.satellite, now)
        shown.append(AlertView("silenced" if quiet and r.status == AlertStatus.FIRING else r.status, r))
    return AlertsView(tuple(shown), tuple(state.silences(now)), len(state.deliveries(DeliveryStatus.PENDING)))
