"""Delivery channels: a log file, email (SMTP with STARTTLS and a verified TLS context), Slack webhook.

A send either succeeds, fails for now (``Transient``: the queue retries later), or fails for good
(``Permanent``: a configuration error, logged, not retried). No message or log line ever contains the
webhook URL or a password.
"""

from __future__ import annotations

import datetime as dt
import json
import logging
import smtplib
import ssl
import time
from collections.abc import Callable
from email.message import EmailMessage
from pathlib import Path
from typing import Protocol

import requests

from monitor.config.alert_settings import AlertSettings, EmailSettings, SlackSettings
from monitor.config.keys import env_secret
from monitor.history.records import Message

LOG = logging.getLogger(__name__)


class Transient(Exception):
    """Try again later (server down, rate limited, 5xx).

    Parameters
    ----------
    message : str
        What went wrong.
    retry_after_s : float, optional
        When to try again, s.
    """

    def __init__(self, message: str, retry_after_s: float = 300.0) -> None:
        super().__init__(message)
        self.retry_after_s = retry_after_s


class Permanent(Exception):
    """A configuration or payload error: retrying will not help."""


class LogChannel:
    """Appends each message to a file (a channel that cannot fail).

    Parameters
    ----------
    path : Path
        The log file (``alerts.log``).
    """

    name = "log"

    def __init__(self, path: Path):
        self.path = Path(path)

    def send(self, msg: Message) -> None:
        """Append *msg* to the log file.

        Parameters
        ----------
        msg : Message
            The message.
        """
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path, "a") as fh:
            fh.write(f"--- {dt.datetime.now(dt.timezone.utc).isoformat(timespec='seconds')} {msg.subject}\n")
            fh.write(msg.text.rstrip() + "\n")


class EmailChannel:
    """SMTP with STARTTLS and a verified certificate; the trend plot attached.

    Parameters
    ----------
    settings : EmailSettings
        The ``alerts.email`` section.
    """

    name = "email"

    def __init__(self, settings: EmailSettings) -> None:
        self.s = settings

    def send(self, msg: Message) -> None:
        """Send *msg* as a multipart e-mail with its attachments; raises on failure (the queue retries).

        Parameters
        ----------
        msg : Message
            The message.
        """
        s = self.s
        m = EmailMessage()
        m["Subject"] = msg.subject
        m["From"] = s.sender
        m["To"] = ", ".join(s.to)
        m.set_content(msg.text)
        m.add_alternative(msg.html, subtype="html")
        for a in msg.attachments:
            maintype, _, subtype = a.mime_type.partition("/")
            m.add_attachment(a.content, maintype=maintype, subtype=subtype, filename=a.filename)
        user, password = env_secret(s.username_env), env_secret(s.password_env)
        try:
            with smtplib.SMTP(s.host, s.port, timeout=s.timeout_s) as smtp:
                if s.starttls:
                    smtp.starttls(
                        context=ssl.create_default_context(cafile=str(s.cafile) if s.cafile else None)
                    )
                if user:
                    smtp.login(user, password or "")
                smtp.send_message(m)
        except smtplib.SMTPAuthenticationError as exc:
            raise Permanent(f"SMTP login refused for the configured user ({exc.smtp_code})") from None
        except (smtplib.SMTPNotSupportedError, ssl.SSLCertVerificationError) as exc:
            raise Permanent(f"SMTP TLS problem: {type(exc).__name__}: {exc}") from None
        except smtplib.SMTPResponseException as exc:
            if 400 <= exc.smtp_code < 500:
                raise Transient(f"SMTP {exc.smtp_code}") from None
            raise Permanent(f"SMTP {exc.smtp_code} {exc.smtp_error!r}") from None
        except (OSError, smtplib.SMTPException) as exc:
            raise Transient(f"SMTP {s.host}:{s.port}: {type(exc).__name__}") from None


class SlackChannel:
    """Slack incoming webhook: 200 ``ok`` is success; 429 honours Retry-After; 5xx is retried; 4xx is
    permanent.

    Parameters
    ----------
    settings : SlackSettings
        The ``alerts.slack`` section.
    sleep : callable, optional
        How a rate-limited retry waits, s.
    """

    name = "slack"

    def __init__(self, settings: SlackSettings, sleep: Callable[[float], None] = time.sleep) -> None:
        self.s = settings
        self.sleep = sleep

    def send(self, msg: Message) -> None:
        """Post *msg* to the webhook; raises on failure (the queue retries).

        Parameters
        ----------
        msg : Message
            The message.
        """
        url = env_secret(self.s.webhook_env)
        if not url:
            raise Permanent(f"Slack webhook: environment variable {self.s.webhook_env} is not set")
        payload = {
            "text": msg.text[:3500],
            "blocks": [{"type": "section", "text": {"type": "mrkdwn", "text": b[:2900]}} for b in msg.blocks],
        }
        delay = 1.0
        for attempt in range(self.s.retries + 1):
            try:
                r = requests.post(
                    url,
                    data=json.dumps(payload),
                    headers={"Content-Type": "application/json"},
                    timeout=self.s.timeout_s,
                )
            except requests.RequestException as exc:
                raise Transient(f"Slack webhook unreachable ({type(exc).__name__})") from None
            if r.status_code == 200 and r.text.strip() == "ok":
                return
            if r.status_code == 429:
                wait = float(r.headers.get("Retry-After", "1") or 1)
                if wait > self.s.max_wait_s or attempt == self.s.retries:
                    raise Transient(f"Slack rate limit, retry after {wait:.0f} s", retry_after_s=wait)
                self.sleep(wait)
                continue
            if r.status_code >= 500:
                if attempt == self.s.retries:
                    raise Transient(f"Slack HTTP {r.status_code}")
                self.sleep(delay)
                delay *= 2
                continue
            raise Permanent(
                f"Slack HTTP {r.status_code} {r.text.strip()[:100]!r}: check the webhook configuration"
            )
        raise Transient("Slack: retries exhausted")


class Channel(Protocol):
    """A way a message leaves the service: :meth:`send` raises :class:`Transient` or :class:`Permanent`."""

    name: str

    def send(self, msg: Message) -> None: ...


def make_channels(settings: AlertSettings) -> dict[str, Channel]:
    """The channels the settings configure, by name.

    Parameters
    ----------
    settings : AlertSettings
        The ``alerts`` section.

    Returns
    -------
    dict of str to Channel
        {name: channel}.
    """
    out: dict[str, Channel] = {}
    if settings.log:
        out["log"] = LogChannel(settings.log)
    if settings.email:
        out["email"] = EmailChannel(settings.email)
    if settings.slack:
        out["slack"] = SlackChannel(settings.slack)
    return out
