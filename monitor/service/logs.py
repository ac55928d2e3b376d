"""The service's log lines: for a terminal, for the systemd journal, or as JSON.

Under systemd (``JOURNAL_STREAM`` is set) every line starts with its syslog priority, ``<3>`` for an error
(sd-daemon(3)): the journal stores it as the line's priority, so ``journalctl -u crisgeo -p err`` finds the
failed runs, and it stamps the time itself. The journal's stream makes an entry of every line, so an event
is kept on one line: the lines of a traceback are joined with `` | `` (one entry per event, not twenty).
On a terminal, times are UTC and say so (``2026-11-25T03:30:01Z``), as every time the service prints.

JSON lines carry the context of the satellite-day they belong to as fields (``satellite``, ``day``,
``stage``, ``run_id``), set by :func:`monitor.core.logcontext.context` around the work.

Libraries speak at WARNING and above: APScheduler alone would write two INFO lines for every 30 s
heartbeat, ~5,800 lines a day (``-v`` brings them back, with everything at DEBUG).
"""

from __future__ import annotations

import datetime as dt
import json
import logging
import os
import time

from monitor.core import logcontext

# syslog priorities of the logging levels (RFC 5424: 2 critical, 3 error, 4 warning, 6 info, 7 debug)
PRIORITY = {logging.CRITICAL: 2, logging.ERROR: 3, logging.WARNING: 4, logging.INFO: 6, logging.DEBUG: 7}
QUIET_LIBRARIES = ("apscheduler", "urllib3", "distributed", "numba", "matplotlib", "h5py", "asyncio")


def priority(levelno: int) -> int:
    """The syslog priority of a logging level (levels in between take the next more severe one).

    Parameters
    ----------
    levelno : int
        A logging level.

    Returns
    -------
    int
        The syslog priority (levels in between take the next more severe one).
    """
    return next((p for level, p in sorted(PRIORITY.items()) if levelno <= level), 2)


class JournalFormatter(logging.Formatter):
    """``<N>LEVEL logger: message``: the journal reads the priority N and adds the time."""

    def __init__(self) -> None:
        super().__init__("%(levelname)s %(name)s: %(message)s")

    def format(self, record: logging.LogRecord) -> str:
        """One line, its priority first; a traceback's lines follow on it, joined by `` | ``.

        Parameters
        ----------
        record : logging.LogRecord
            The record.

        Returns
        -------
        str
            ``<N>logger: message``, one journal entry.
        """
        lines = [line for line in super().format(record).splitlines() if line.strip()]
        return f"<{priority(record.levelno)}>" + " | ".join(line.strip() for line in lines)


class UtcFormatter(logging.Formatter):
    """``2026-11-25T03:30:01Z LEVEL logger: message``: the time in UTC, whatever the host's zone."""

    converter = staticmethod(time.gmtime)

    def __init__(self) -> None:
        super().__init__("%(asctime)s %(levelname)s %(name)s: %(message)s", "%Y-%m-%dT%H:%M:%SZ")


class JsonFormatter(logging.Formatter):
    """One JSON object per line: time (UTC, ISO 8601), level, priority, logger, message, the satellite-day
    context (satellite, day, stage, run_id) where there is one, and the exception."""

    def format(self, record: logging.LogRecord) -> str:
        """One JSON object per record.

        Parameters
        ----------
        record : logging.LogRecord
            The record.

        Returns
        -------
        str
            One JSON object.
        """
        doc = {
            "time": dt.datetime.fromtimestamp(record.created, dt.timezone.utc).isoformat(
                timespec="milliseconds"
            ),
            "level": record.levelname,
            "priority": priority(record.levelno),
            "logger": record.name,
            "message": record.getMessage(),
            **{k: str(v) for k, v in logcontext.fields().items()},
        }
        if record.exc_info:
            doc["exception"] = self.formatException(record.exc_info)
        return json.dumps(doc)


def setup(verbose: bool, log_format: str) -> None:
    """Log to stderr: JSON lines, journal lines (under systemd) or text with a timestamp; libraries at
    WARNING unless *verbose*.

    Parameters
    ----------
    verbose : bool
        DEBUG rather than INFO, and libraries below WARNING.
    log_format : str
        ``text`` or ``json``.
    """
    handler = logging.StreamHandler()
    if log_format == "json":
        handler.setFormatter(JsonFormatter())
    elif os.environ.get("JOURNAL_STREAM"):
        handler.setFormatter(JournalFormatter())
    else:
        handler.setFormatter(UtcFormatter())
    logging.basicConfig(level=logging.DEBUG if verbose else logging.INFO, handlers=[handler], force=True)
    for name in QUIET_LIBRARIES:
        logging.getLogger(name).setLevel(logging.DEBUG if verbose else logging.WARNING)
    # urllib3's debug lines carry request paths (webhook secrets): never below WARNING
    logging.getLogger("urllib3").setLevel(logging.WARNING)
