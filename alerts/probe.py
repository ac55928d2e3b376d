"""A test notification: one clearly marked message through each configured channel (or one named), to check
the SMTP, Slack and Alertmanager wiring before an alert needs it.

It is sent directly, not through the queue, and reported per channel: delivered, or why not (the channel's
own :class:`alerts.channels.Transient` or :class:`alerts.channels.Permanent` reason). It touches nothing the
service keeps: no alert state, no delivery row, no line in the alert log (the log channel records alerts
only, so it is not probed), nothing in ``/metrics``. In Alertmanager it is an alert labelled ``test="true"``
(``alertname`` ``crisgeo_test``) that ends :data:`ALERTMANAGER_MINUTES` after it is sent, so a route or
an inhibition can tell it apart and it leaves by itself.
"""

from __future__ import annotations

import datetime as dt
import html
import socket
from dataclasses import dataclass

import requests

from alerts.alertmanager import timestamp
from alerts.channels import Permanent, Transient, make_channels
from monitor.config.alert_settings import AlertSettings
from monitor.history.records import Message

ALERTMANAGER_MINUTES = 5  # how long the test alert stays in Alertmanager
PROBED = ("email", "slack", "alertmanager")  # the channels a test message goes through


@dataclass(frozen=True)
class ProbeOutcome:
    """What the test message did on one channel: *delivered*, else *reason*."""

    channel: str
    delivered: bool
    reason: str = ""

    def text(self) -> str:
        """``email: delivered`` or ``slack: not delivered: <reason>``.

        Returns
        -------
        str
            The line.
        """
        return f"{self.channel}: " + ("delivered" if self.delivered else f"not delivered: {self.reason}")


def configured(settings: AlertSettings) -> list[str]:
    """The channels of *settings* a test message can go through, in :data:`PROBED` order.

    Parameters
    ----------
    settings : AlertSettings
        The ``alerts`` section.

    Returns
    -------
    list of str
        The channels.
    """
    have = set(make_channels(settings)) | ({"alertmanager"} if settings.alertmanager else set())
    return [c for c in PROBED if c in have]


def probe_message(now: dt.datetime, prefix: str) -> Message:
    """The message: marked TEST in its subject and first line, saying that nothing is wrong.

    Parameters
    ----------
    now : datetime.datetime
        Now, UTC.
    prefix : str
        The subject's prefix (``alerts.subject_prefix``).

    Returns
    -------
    Message
        The message.
    """
    host = socket.gethostname()
    subject = f"{prefix} TEST notification from {host}: no action needed"
    text = (
        f"TEST: a test notification of crisgeo on {host}, sent {now:%Y-%m-%d %H:%M:%S} UTC by "
        "`crisgeo alerts test`. No alert is firing because of it; nothing needs doing."
    )
    return Message(
        subject,
        text,
        f"<html><body><h3>{html.escape(subject)}</h3><p>{html.escape(text)}</p></body></html>",
        (f"*TEST* {text}",),
    )


def probe(
    settings: AlertSettings, only: str | None = None, now: dt.datetime | None = None
) -> list[ProbeOutcome]:
    """Send the test message through every configured channel of :data:`PROBED`, or *only* that one; the
    outcome per channel. ValueError when *only* is not configured.

    Parameters
    ----------
    settings : AlertSettings
        The ``alerts`` section.
    only : str, optional
        Only this channel.
    now : datetime.datetime, optional
        Now, UTC; the clock's by default.

    Returns
    -------
    list of ProbeOutcome
        Per channel.
    """
    now = now or dt.datetime.now(dt.timezone.utc)
    names = configured(settings)
    if only is not None:
        if only not in names:
            have = ", ".join(names) or "none"
            raise ValueError(f"channel {only!r} is not configured (configured: {have})")
        names = [only]
    msg = probe_message(now, settings.subject_prefix)
    channels = make_channels(settings)
    out = []
    for name in names:
        try:
            if name == "alertmanager":
                _alertmanager(settings, msg, now)
            else:
                channels[name].send(msg)
        except (Transient, Permanent) as exc:
            out.append(ProbeOutcome(name, False, str(exc)))
        else:
            out.append(ProbeOutcome(name, True))
    return out


def _alertmanager(settings: AlertSettings, msg: Message, now: dt.datetime) -> None:
    """Post the test alert (labels ``test="true"``, ending in :data:`ALERTMANAGER_MINUTES`)."""
    am = settings.alertmanager
    assert am is not None
    ends = now + dt.timedelta(minutes=ALERTMANAGER_MINUTES)
    alert = {
        "labels": {"alertname": "crisgeo_test", "service": "crisgeo", "severity": "none", "test": "true"},
        "annotations": {"summary": msg.subject, "description": msg.text},
        "startsAt": timestamp(now),
        "endsAt": timestamp(ends),
    }
    url = am.url + "/api/v2/alerts"
    try:
        r = requests.post(url, json=[alert], timeout=am.timeout_s, allow_redirects=False)
    except requests.RequestException as exc:
        raise Transient(f"Alertmanager {url} unreachable ({type(exc).__name__})") from None
    if r.status_code != 200:
        raise Permanent(f"Alertmanager {url}: HTTP {r.status_code} {r.text.strip()[:100]!r}")
