"""The service's log lines: for a terminal, for the systemd journal, or as JSON.

Under systemd, stderr is connected to the journal when ``JOURNAL_STREAM`` names stderr's own device and
inode (systemd.exec(5): a child that inherited the variable with another stderr is not). Then each record is
sent to journald's native socket as an entry with fields (systemd.journal-fields(7), the native protocol
of sd_journal_sendv(3)): ``MESSAGE``, ``PRIORITY``, ``SYSLOG_IDENTIFIER``, the logger, and the satellite-day
the line belongs to (``SATELLITE``, ``DAY``, ``STAGE``, ``RUN_ID``), and ``ALERT`` on an alert's line: so
``journalctl SATELLITE=j01`` or ``journalctl ALERT=spec:j01`` finds them. Where the socket cannot be
reached, every line goes to the stream starting with its syslog priority, ``<3>`` for an error
(sd-daemon(3)): the journal stores it as the line's priority, so ``journalctl -u crisgeo -p err`` finds the
failed runs, and it stamps the time itself. An event is kept on one line: the lines of a traceback are
joined with `` | `` (one entry per event, not twenty).
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
import socket
import struct
import sys
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


# journald's native protocol (systemd-journald.service(8)); CRISGEO_JOURNAL_SOCKET names another place (a
# container with the host's journald socket mounted elsewhere)
JOURNAL_SOCKET = os.environ.get("CRISGEO_JOURNAL_SOCKET", "/run/systemd/journal/socket")
IDENTIFIER = "crisgeo"


def journal_is_stderr(environ: dict | None = None, fd: int = 2) -> bool:
    """Whether stderr is the journal's stream: ``JOURNAL_STREAM`` (``DEVICE:INODE``) names stderr's own
    device and inode, as systemd.exec(5) says to check.

    Parameters
    ----------
    environ : dict, optional
        The environment; the process's by default.
    fd : int, optional
        The descriptor checked (stderr).

    Returns
    -------
    bool
        True when the journal reads this stderr.
    """
    dev, _, ino = (os.environ if environ is None else environ).get("JOURNAL_STREAM", "").partition(":")
    try:
        st = os.fstat(fd)
    except OSError:
        return False
    return dev.isdigit() and ino.isdigit() and (int(dev), int(ino)) == (st.st_dev, st.st_ino)


def journal_fields(record: logging.LogRecord, message: str) -> dict[str, str]:
    """The fields of a record's journal entry: the message and its priority, the identifier and logger,
    the satellite-day context and, on an alert's line, the alert.

    Parameters
    ----------
    record : logging.LogRecord
        The record.
    message : str
        The record formatted (a traceback joined on one line).

    Returns
    -------
    dict
        Field name (upper case, as journald wants) to value.
    """
    fields = {
        "MESSAGE": message,
        "PRIORITY": str(priority(record.levelno)),
        "SYSLOG_IDENTIFIER": IDENTIFIER,
        "LOGGER": record.name,
        "CODE_FILE": str(record.pathname),
        "CODE_LINE": str(record.lineno),
        "CODE_FUNC": str(record.funcName or ""),
    }
    fields |= {k.upper(): str(v) for k, v in logcontext.fields().items()}
    alert = getattr(record, "alert", None)
    if alert:
        fields["ALERT"] = str(alert)
    return fields


def encode_entry(fields: dict[str, str]) -> bytes:
    """A journal entry in the native protocol: ``KEY=value`` lines; a value with a newline as ``KEY``, its
    length (64-bit little-endian) and its bytes.

    Parameters
    ----------
    fields : dict
        Field name to value.

    Returns
    -------
    bytes
        The datagram.
    """
    out = bytearray()
    for key, value in fields.items():
        data = value.encode("utf-8", "replace")
        if b"\n" in data:
            out += key.encode() + b"\n" + struct.pack("<Q", len(data)) + data + b"\n"
        else:
            out += key.encode() + b"=" + data + b"\n"
    return bytes(out)


class JournalHandler(logging.Handler):
    """Each record an entry with fields on journald's native socket (:func:`journal_fields`); a record
    the socket does not take goes to stderr as a priority-prefixed line, so nothing is lost.

    Parameters
    ----------
    path : str, optional
        journald's socket.
    """

    def __init__(self, path: str = JOURNAL_SOCKET) -> None:
        super().__init__()
        self.path = path
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
        self.fallback = JournalFormatter()
        self.setFormatter(JournalFormatter())

    def emit(self, record: logging.LogRecord) -> None:
        """Send the record's entry (a line on stderr where the socket refuses it).

        Parameters
        ----------
        record : logging.LogRecord
            The record.
        """
        try:
            line = self.format(record)
            message = line[line.index(">") + 1 :]
            self.sock.sendto(encode_entry(journal_fields(record, message)), self.path)
        except OSError:
            sys.stderr.write(self.fallback.format(record) + "\n")
        except Exception:  # noqa: BLE001 - logging never raises into the service
            self.handleError(record)

    def close(self) -> None:
        """Close the socket."""
        self.sock.close()
        super().close()


def setup(verbose: bool, log_format: str) -> None:
    """Log to stderr: JSON lines, journal entries with fields (stderr being the journal's stream) or text
    with a timestamp; libraries at WARNING unless *verbose*.

    Parameters
    ----------
    verbose : bool
        DEBUG rather than INFO, and libraries below WARNING.
    log_format : str
        ``text`` or ``json``.
    """
    handler: logging.Handler = logging.StreamHandler()
    if log_format == "json":
        handler.setFormatter(JsonFormatter())
    elif journal_is_stderr():
        if os.path.exists(JOURNAL_SOCKET):
            handler = JournalHandler(JOURNAL_SOCKET)
        else:
            handler.setFormatter(JournalFormatter())
    else:
        handler.setFormatter(UtcFormatter())
    logging.basicConfig(level=logging.DEBUG if verbose else logging.INFO, handlers=[handler], force=True)
    for name in QUIET_LIBRARIES:
        logging.getLogger(name).setLevel(logging.DEBUG if verbose else logging.WARNING)
    # urllib3's debug lines carry request paths (webhook secrets): never below WARNING
    logging.getLogger("urllib3").setLevel(logging.WARNING)
