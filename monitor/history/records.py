"""What the store gives back, typed: its rows as records, and the interfaces the alerts program against.

The store (:mod:`monitor.service.store`) writes and reads SQLite; whoever reads history through it (the alert
rules, the report, the CLI) receives these records. The alerts read the store as a :class:`History` and write
to it through an :class:`AlertBook` alone (their ledger, their noise fits), so that ``alerts`` needs nothing
of ``monitor`` above this floor; what they queue for a channel is a :class:`Message`.
"""

from __future__ import annotations

import base64
import datetime as dt
import json
from collections.abc import Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from monitor.core.result import RELIABILITY_FLAGS, ForOffset
from monitor.core.vocabulary import (
    AlertStatus,
    DeliveryStatus,
    EventKind,
    RunStatus,
    Severity,
)


class FindingRecord(Protocol):
    """What the alert ledger records of a rule's finding (:class:`alerts.rules.Finding`, a floor above)."""

    @property  # numpydoc ignore=RT01
    def alert_id(self) -> str: ...
    @property  # numpydoc ignore=RT01
    def rule(self) -> str: ...
    @property  # numpydoc ignore=RT01
    def satellite(self) -> str: ...
    @property  # numpydoc ignore=RT01
    def group(self) -> str: ...
    @property  # numpydoc ignore=RT01
    def severity(self) -> Severity: ...
    @property  # numpydoc ignore=RT01
    def summary(self) -> str: ...
    @property  # numpydoc ignore=RT01
    def lines(self) -> list[str]: ...


@dataclass(frozen=True)
class Attachment:
    """A file a message carries (an e-mail attaches it): its name, its bytes and their MIME type."""

    filename: str
    content: bytes
    mime_type: str = "image/png"


@dataclass(frozen=True)
class Message:
    """One notification for a satellite, as every channel sends it: the subject, the plain text, its HTML
    form (e-mail), its Slack blocks (mrkdwn, already escaped), and what an e-mail attaches."""

    subject: str
    text: str
    html: str
    blocks: tuple[str, ...] = ()
    attachments: tuple[Attachment, ...] = field(default=())

    def to_json(self) -> str:
        """The message as the delivery queue keeps it (attachments in base64).

        Returns
        -------
        str
            JSON.
        """
        return json.dumps(
            {
                "subject": self.subject,
                "text": self.text,
                "html": self.html,
                "blocks": list(self.blocks),
                "attachments": [
                    {
                        "filename": a.filename,
                        "mime_type": a.mime_type,
                        "base64": base64.b64encode(a.content).decode(),
                    }
                    for a in self.attachments
                ],
            }
        )

    @classmethod
    def from_json(cls, body: str) -> "Message":
        """The message of a queued delivery's body.

        Parameters
        ----------
        body : str
            JSON as :meth:`to_json` writes it.

        Returns
        -------
        Message
            The message.
        """
        d = json.loads(body)
        return cls(
            d["subject"],
            d["text"],
            d.get("html", ""),
            tuple(d.get("blocks", ())),
            # a version before 1.1 queued the report's path instead of the bytes: such a message goes without
            tuple(
                Attachment(a["filename"], base64.b64decode(a["base64"]), a["mime_type"])
                for a in d.get("attachments", ())
                if isinstance(a, dict)
            ),
        )


class Row(Protocol):
    """A row of the store (:class:`sqlite3.Row`): its columns by name."""

    def __getitem__(self, key: str, /) -> Any: ...


def iso(t: dt.datetime) -> str:
    """*t* as an ISO 8601 UTC string, to the second.

    Parameters
    ----------
    t : datetime.datetime
        An aware time.

    Returns
    -------
    str
        ISO 8601, UTC, to the second.
    """
    return t.astimezone(dt.timezone.utc).isoformat(timespec="seconds")


@dataclass(frozen=True)
class Alert:
    """One alert: identified by *alert_id* (rule:satellite[:group]); *status* firing or resolved; times ISO
    8601 UTC; *lines* the finding's detail lines."""

    alert_id: str
    rule: str
    satellite: str
    grp: str | None
    severity: Severity | None
    status: AlertStatus
    started: str | None
    last_notified: str | None
    resolved: str | None
    summary: str | None
    lines: list[str]

    @classmethod
    def from_row(cls, r: Row) -> "Alert":
        """The Alert of a row of the store.

        Parameters
        ----------
        r : sqlite3.Row
            The row.

        Returns
        -------
        Alert
            The record.
        """
        d = {k: r[k] for k in cls.__dataclass_fields__ if k != "alert_id"}
        d["alert_id"] = r["fingerprint"]  # the store's column keeps its first name
        d["lines"] = json.loads(r["lines"] or "[]")
        d["status"] = AlertStatus(d["status"])
        d["severity"] = Severity(d["severity"]) if d["severity"] else None
        return cls(**d)


@dataclass(frozen=True)
class Silence:
    """A silence: *rule* and *satellite* (None: all) are quiet until *until* (ISO 8601 UTC), for *reason*."""

    id: int
    rule: str | None
    satellite: str | None
    until: str
    reason: str
    created: str | None

    @classmethod
    def from_row(cls, r: Row) -> "Silence":
        """The Silence of a row of the store.

        Parameters
        ----------
        r : sqlite3.Row
            The row.

        Returns
        -------
        Silence
            The record.
        """
        return cls(**{k: r[k] for k in cls.__dataclass_fields__})


@dataclass(frozen=True)
class Delivery:
    """A queued notification: *body* the message, *status* pending, sending, sent or failed, after *attempts*
    tries; times ISO 8601 UTC."""

    id: int
    channel: str
    satellite: str | None
    subject: str
    body: Message
    created: str
    status: DeliveryStatus
    attempts: int
    next_attempt: str | None
    last_error: str | None
    sent: str | None

    @classmethod
    def from_row(cls, r: Row) -> "Delivery":
        """The Delivery of a row of the store.

        Parameters
        ----------
        r : sqlite3.Row
            The row.

        Returns
        -------
        Delivery
            The record.
        """
        d = {k: r[k] for k in cls.__dataclass_fields__}
        return cls(
            **{
                **d,
                "body": Message.from_json(d["body"]),
                "attempts": int(d["attempts"] or 0),
                "status": DeliveryStatus(d["status"]),
            }
        )


@dataclass(frozen=True)
class Event:
    """One ``events`` row; *detail* is the decoded JSON (rows of older versions, plain text, become
    ``{"text": ...}``)."""

    id: int
    time: str
    kind: EventKind
    satellite: str | None
    detail: dict

    @classmethod
    def from_row(cls, r: Row) -> "Event":
        """The event of an ``events`` row.

        Parameters
        ----------
        r : sqlite3.Row
            The row.

        Returns
        -------
        Event
            The record.
        """
        try:
            detail = json.loads(r["detail"])
        except (TypeError, ValueError):
            detail = None
        if not isinstance(detail, dict):
            detail = {"text": r["detail"]}
        return cls(r["id"], r["time"], EventKind(r["kind"]), r["satellite"], detail)


@dataclass(frozen=True)
class Run:
    """One run of the ledger; times ISO 8601 UTC (*finished* None while running); *day* YYYY-MM-DD."""

    id: int
    satellite: str
    day: str
    started: str
    finished: str | None
    status: RunStatus
    reason: str | None
    n_granules: int
    summary: str | None

    @classmethod
    def from_row(cls, r: Row) -> "Run":
        """The Run of a row of the store.

        Parameters
        ----------
        r : sqlite3.Row
            The row.

        Returns
        -------
        Run
            The record.
        """
        row = {k: r[k] for k in cls.__dataclass_fields__}
        return cls(**{**row, "status": RunStatus(row["status"])})


def last_success(runs: Sequence[Run]) -> dt.datetime | None:
    """When the latest successful run (status ok) of *runs* (in order) finished, UTC; if none succeeded,
    when the first began; None without runs. Empty days (no data at the source) are not a success.

    Parameters
    ----------
    runs : sequence of Run
        A satellite's runs, in order.

    Returns
    -------
    datetime.datetime or None
        UTC.
    """
    if not runs:
        return None
    ok = [r for r in runs if r.status == RunStatus.OK]
    since = dt.datetime.fromisoformat((ok[-1].finished or ok[-1].started) if ok else runs[0].started)
    return since if since.tzinfo else since.replace(tzinfo=dt.timezone.utc)


@dataclass(frozen=True)
class ForSeries:
    """The per-FOR results of one satellite over days, as arrays: *days* ascending (dates); *values* per
    measured field an array (days, N_FOR), NaN where nothing is stored (n_samples 0); *flags* a
    (days, N_FOR) object array of flag-name tuples; *stored* where a result is."""

    days: list
    values: dict
    flags: np.ndarray
    stored: np.ndarray

    def __len__(self) -> int:
        return len(self.days)

    def reliable(self) -> np.ndarray:
        """(days, N_FOR): a stored FOR without any of the reliability flags.

        Returns
        -------
        numpy.ndarray
            bool per day and FOR: no reliability flag set.
        """
        flagged = np.vectorize(lambda f: bool(set(f) & set(RELIABILITY_FLAGS)), otypes=[bool])(self.flags)
        return self.stored & ~flagged if self.flags.size else self.stored


def _json_list(text: str | None) -> tuple:
    return tuple(json.loads(text)) if text else ()


@dataclass(frozen=True)
class GranuleRow:
    """One assessed CrIS granule as stored: its files and VIIRS cover, usable FOVs, and the processing
    metadata (SDR software and algorithm versions, auxiliary files) that change attribution compares from
    day to day; *day* YYYY-MM-DD, *start* ISO 8601."""

    satellite: str
    day: str
    run_id: int
    granule_id: str
    start: str | None
    cris_geo: str | None
    cris_sdr: str | None
    viirs: tuple[str, ...]
    n_usable: int | None
    software_version: str | None
    algorithm_version: str | None
    cris_aux: tuple[str, ...]
    viirs_aux: tuple[str, ...]
    viirs_software: str | None

    @classmethod
    def from_row(cls, r: Row) -> "GranuleRow":
        """The GranuleRow of a row of the store.

        Parameters
        ----------
        r : sqlite3.Row
            The row.

        Returns
        -------
        GranuleRow
            The record.
        """
        row = {k: r[k] for k in cls.__dataclass_fields__}
        return cls(**{**row, **{k: _json_list(row[k]) for k in ("viirs", "cris_aux", "viirs_aux")}})


@dataclass(frozen=True)
class SelectionRow:
    """One scene-selection decision: the granule, its inhomogeneity score (K), kept or rejected and why."""

    satellite: str
    day: str
    run_id: int
    granule: str
    score_k: float | None
    decision: str
    reason: str | None

    @classmethod
    def from_row(cls, r: Row) -> "SelectionRow":
        """The SelectionRow of a row of the store.

        Parameters
        ----------
        r : sqlite3.Row
            The row.

        Returns
        -------
        SelectionRow
            The record.
        """
        return cls(**{k: r[k] for k in cls.__dataclass_fields__})


class AlertLedger(Protocol):
    """The alert state, silences and delivery queue
    (:class:`monitor.service.store.alert_state.AlertState`)."""

    def get(self, alert_id: str) -> Alert | None: ...
    def firing(self, satellite: str | None = None) -> list[Alert]: ...
    def all(self) -> list[Alert]: ...
    def upsert(self, finding: FindingRecord, now: dt.datetime, notified: bool) -> None: ...
    def resolve(self, alert_id: str, now: dt.datetime) -> None: ...
    def silenced(self, rule: str, satellite: str, now: dt.datetime) -> Silence | None: ...
    def silences(self, now: dt.datetime) -> list[Silence]: ...
    def enqueue(self, channel: str, satellite: str, message: Message, now: dt.datetime) -> None: ...
    def due(self, now: dt.datetime) -> list[Delivery]: ...
    def claim(self, delivery_id: int, now: dt.datetime, lease_s: float = 600.0) -> bool: ...
    def deliveries(self, status: DeliveryStatus | None = None) -> list[Delivery]: ...
    def mark(
        self,
        delivery_id: int,
        status: DeliveryStatus,
        now: dt.datetime,
        error: str | None = ...,
        retry_after_s: float = ...,
    ) -> None: ...


class History(Protocol):
    """What the alert rules, the report and the export read of the store
    (:class:`monitor.service.store.sqlite.Store`); nothing here writes."""

    path: Path  # the store's file

    def runs(self, satellite: str | None = None) -> list[Run]: ...
    def runs_since_success(self, satellite: str) -> list[Run]: ...
    def events(self, kind: EventKind | None = None) -> list[Event]: ...
    def day_result(self, satellite: str, day: dt.date) -> list[ForOffset]: ...
    def latest_day(self, satellite: str) -> dt.date | None: ...
    def series(
        self,
        satellite: str,
        since: dt.date | None = None,
        until: dt.date | None = None,
        fields: Sequence[str] | None = None,
    ) -> ForSeries: ...
    def noise_fit(self, satellite: str, quantity: str, before: dt.date) -> dict | None: ...
    def granules(
        self, satellite: str, day: dt.date | None = None, since: dt.date | None = None
    ) -> list[GranuleRow]: ...
    def fingerprint(self, satellite: str, before: dt.date) -> tuple[dt.date, dict] | None: ...


class AlertBook(Protocol):
    """What the alerts write to the store, and through nothing else: their ledger (state, silences, the
    delivery queue) and the jump rule's noise fits, in the store's transactions."""

    def alert_state(self) -> AlertLedger: ...
    def transaction(self) -> AbstractContextManager[Any]: ...
    def keep_noise_fit(self, satellite: str, quantity: str, before: dt.date, body: dict) -> None: ...


class AlertStore(History, AlertBook, Protocol):
    """The store as the alert engine is handed it: the history it reads and the book it writes."""
