"""Alertmanager as the alerts' destination: the service's alert state posted to its API v2.

Alertmanager keeps alerts that clients post to ``POST /api/v2/alerts`` and routes, groups, inhibits and
silences them by label. Its model is a state, not messages: a client re-posts each firing alert before
the alert's ``endsAt`` passes, and posts it with ``endsAt`` = the resolution time once resolved. So here
each evaluation (after every run, and hourly) posts the whole state: every alert firing and not silenced
in the service, ending ``validity_hours`` from now (if the service stops posting, Alertmanager ends it
then: the dead-man's rule says why), and every alert resolved within that window, ending when it was
resolved. A post is idempotent (same labels, same alert), so a failed post loses nothing: the next
evaluation sends the state again. No queue, no retries beyond that.

Labels: ``alertname`` (``crisgeo_<rule>``), ``service`` = crisgeo, ``satellite``, ``rule``, ``severity``
and ``group`` (the FOR group of a jump). Annotations: ``summary``, ``description`` (the message's lines),
``report`` and ``dashboard`` links where configured.
"""

from __future__ import annotations

import datetime as dt
import logging

import requests

from monitor.config.alert_settings import AlertSettings
from monitor.core.vocabulary import Severity
from monitor.history.records import AlertBook

LOG = logging.getLogger(__name__)
UTC = dt.timezone.utc


def timestamp(t: dt.datetime) -> str:
    """*t* as Alertmanager's API writes times: RFC 3339 in UTC, to the second.

    Parameters
    ----------
    t : datetime.datetime
        An aware time.

    Returns
    -------
    str
        RFC 3339, UTC, to the second.
    """
    return t.astimezone(UTC).isoformat(timespec="seconds").replace("+00:00", "Z")


def alertmanager_alerts(store: AlertBook, settings: AlertSettings, now: dt.datetime) -> list[dict]:
    """The Alertmanager API v2 alert objects of the service's current state (see the module docstring).

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
    list of dict
        The alert objects.
    """
    am = settings.alertmanager
    if am is None:
        return []
    state = store.alert_state()
    horizon = now - dt.timedelta(hours=am.validity_hours)
    out = []
    for a in state.all():
        if a.severity == Severity.INFO:  # recorded, never sent
            continue
        if a.status == "firing":
            if state.silenced(a.rule, a.satellite, now) is not None:
                continue
            ends = now + dt.timedelta(hours=am.validity_hours)
        elif a.status == "resolved" and a.resolved and dt.datetime.fromisoformat(a.resolved) >= horizon:
            ends = dt.datetime.fromisoformat(a.resolved)
        else:
            continue
        labels = {
            "alertname": f"crisgeo_{a.rule}",
            "service": "crisgeo",
            "satellite": a.satellite or "",
            "rule": a.rule,
            "severity": a.severity or "",
        }
        if a.grp:
            labels["group"] = a.grp
        annotations = {"summary": a.summary or a.rule, "description": "\n".join(a.lines or [])}
        if settings.links.report_url:
            annotations["report"] = f"{settings.links.report_url.rstrip('/')}/{a.satellite}/"
        if settings.links.dashboard_url:
            annotations["dashboard"] = settings.links.dashboard_url
        alert = {
            "labels": labels,
            "annotations": annotations,
            "startsAt": timestamp(dt.datetime.fromisoformat(a.started) if a.started else now),
            "endsAt": timestamp(ends),
        }
        if settings.links.dashboard_url:
            alert["generatorURL"] = settings.links.dashboard_url
        out.append(alert)
    return out


def post_state(store: AlertBook, settings: AlertSettings, now: dt.datetime | None = None) -> int | None:
    """Post the alert state to Alertmanager; the number of alerts posted, or None when the post failed
    (logged: the next evaluation posts the state again). Never raises.

    Parameters
    ----------
    store : AlertBook
        The alerts' book in the store.
    settings : AlertSettings
        The ``alerts`` section.
    now : datetime.datetime, optional
        Now, UTC; the clock's by default.

    Returns
    -------
    int or None
        The alerts posted; None when the post failed.
    """
    if settings.alertmanager is None:
        return None
    now = now or dt.datetime.now(UTC)
    alerts = alertmanager_alerts(store, settings, now)
    if not alerts:
        return 0
    url = settings.alertmanager.url + "/api/v2/alerts"
    try:
        r = requests.post(url, json=alerts, timeout=settings.alertmanager.timeout_s, allow_redirects=False)
    except requests.RequestException as exc:
        LOG.warning("alertmanager %s: %s; the state is posted again at the next evaluation", url, exc)
        return None
    if r.status_code != 200:
        LOG.warning(
            "alertmanager %s: HTTP %d (%s); the state is posted again at the next evaluation",
            url,
            r.status_code,
            r.text[:200],
        )
        return None
    return len(alerts)
