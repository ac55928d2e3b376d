"""Alert state, silences and the delivery queue: the alert tables of the store (created by its migrations)."""

from __future__ import annotations

import datetime as dt
import json
import sqlite3
from contextlib import AbstractContextManager
from typing import Any, Protocol

from monitor.core.vocabulary import AlertStatus, DeliveryStatus
from monitor.history.records import Alert, Delivery, FindingRecord, Message, Silence, iso


class SilenceError(ValueError):
    """A silence that cannot be set or lifted, said in one line."""


class Database(Protocol):
    """What the alert tables need of the store (:class:`monitor.service.store.sqlite.Store`): its connection
    and its transactions. Typed so, this module and the store's do not import each other."""

    db: sqlite3.Connection

    def transaction(self) -> AbstractContextManager[Any]: ...


class AlertState:
    """Alert rows keyed by the alert's identity (rule:satellite:group), silences and queued deliveries.

    Parameters
    ----------
    store : Database
        The store.
    """

    def __init__(self, store: Database):
        self.store = store
        self.db = store.db

    def get(self, alert_id: str) -> Alert | None:
        """The alert row of *alert_id* (rule:satellite:group), or None.

        Parameters
        ----------
        alert_id : str
            rule:satellite:group.

        Returns
        -------
        Alert or None
            The row.
        """
        r = self.db.execute("SELECT * FROM alert_state WHERE fingerprint=?", (alert_id,)).fetchone()
        return Alert.from_row(r) if r else None

    def firing(self, satellite: str | None = None) -> list[Alert]:
        """The alerts firing now (of *satellite*).

        Parameters
        ----------
        satellite : str, optional
            Only this satellite.

        Returns
        -------
        list of Alert
            The alerts firing.
        """
        q = "SELECT * FROM alert_state WHERE status=?" + (" AND satellite=?" if satellite else "")
        args = (AlertStatus.FIRING, satellite) if satellite else (AlertStatus.FIRING,)
        return [Alert.from_row(r) for r in self.db.execute(q, args)]

    def all(self) -> list[Alert]:
        """Every alert, firing or resolved.

        Returns
        -------
        list of Alert
            Every alert.
        """
        q = "SELECT * FROM alert_state ORDER BY satellite, rule, grp"
        return [Alert.from_row(r) for r in self.db.execute(q)]

    def upsert(self, finding: FindingRecord, now: dt.datetime, notified: bool) -> None:
        """Record *finding* as firing (keeping its start while it fires); *notified* stamps the notification
        time.

        Parameters
        ----------
        finding : FindingRecord
            What a rule found.
        now : datetime.datetime
            Now, UTC.
        notified : bool
            Stamp the notification time.
        """
        prev = self.get(finding.alert_id)
        started = prev.started if prev and prev.status == AlertStatus.FIRING else iso(now)
        last = iso(now) if notified else (prev.last_notified if prev else None)
        self.db.execute(
            "INSERT OR REPLACE INTO alert_state VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
            (
                finding.alert_id,
                finding.rule,
                finding.satellite,
                finding.group,
                finding.severity,
                AlertStatus.FIRING,
                started,
                last,
                None,
                finding.summary,
                json.dumps(finding.lines),
            ),
        )

    def resolve(self, alert_id: str, now: dt.datetime) -> None:
        """Mark an alert resolved at *now*.

        Parameters
        ----------
        alert_id : str
            rule:satellite:group.
        now : datetime.datetime
            Now, UTC.
        """
        self.db.execute(
            "UPDATE alert_state SET status=?, resolved=? WHERE fingerprint=?",
            (AlertStatus.RESOLVED, iso(now), alert_id),
        )

    # -- silences
    def silence(
        self, rule: str | None, satellite: str | None, until: dt.datetime, reason: str, now: dt.datetime
    ) -> None:
        """Silence *rule* (None: all) of *satellite* (None: all) until *until*, with a reason; a silence
        without a reason or ending before *now* is refused (:class:`SilenceError`).

        Parameters
        ----------
        rule : str or None
            The rule; None: all.
        satellite : str or None
            The satellite; None: all.
        until : datetime.datetime
            When it ends, UTC.
        reason : str
            Why.
        now : datetime.datetime
            Now, UTC.
        """
        if not reason.strip():
            raise SilenceError("alerts silence needs --expires and --reason")
        if until <= now:
            raise SilenceError("--until must be in the future")
        with self.store.transaction():
            self.db.execute(
                "INSERT INTO silences (rule, satellite, until, reason, created) VALUES (?, ?, ?, ?, ?)",
                (rule, satellite, iso(until), reason, iso(now)),
            )

    def lift(self, silence_id: int, now: dt.datetime) -> None:
        """End the silence *silence_id* now (kept, as history); no such silence in force is a
        :class:`SilenceError`.

        Parameters
        ----------
        silence_id : int
            The silence.
        now : datetime.datetime
            Now, UTC.
        """
        with self.store.transaction():
            cur = self.db.execute(
                "UPDATE silences SET until=? WHERE id=? AND until > ?", (iso(now), silence_id, iso(now))
            )
        if cur.rowcount != 1:
            raise SilenceError(f"--id {silence_id}: no silence in force has that number")

    def silenced(self, rule: str, satellite: str, now: dt.datetime) -> Silence | None:
        """The silence in force for *rule* and *satellite* at *now*, or None.

        Parameters
        ----------
        rule : str
            The rule.
        satellite : str
            The satellite's short name.
        now : datetime.datetime
            Now, UTC.

        Returns
        -------
        Silence or None
            The silence in force.
        """
        r = self.db.execute(
            "SELECT * FROM silences WHERE until > ? AND (rule IS NULL OR rule=?) "
            "AND (satellite IS NULL OR satellite=?) ORDER BY until DESC",
            (iso(now), rule, satellite),
        ).fetchone()
        return Silence.from_row(r) if r else None

    def silences(self, now: dt.datetime) -> list[Silence]:
        """The silences in force at *now*.

        Parameters
        ----------
        now : datetime.datetime
            Now, UTC.

        Returns
        -------
        list of Silence
            Those in force.
        """
        return [
            Silence.from_row(r)
            for r in self.db.execute("SELECT * FROM silences WHERE until > ? ORDER BY until", (iso(now),))
        ]

    # -- delivery queue
    def enqueue(self, channel: str, satellite: str, message: Message, now: dt.datetime) -> None:
        """Queue *message* for delivery on *channel*.

        Parameters
        ----------
        channel : str
            ``email``, ``slack``, ``alertmanager``.
        satellite : str
            The satellite's short name.
        message : Message
            The notification.
        now : datetime.datetime
            Now, UTC.
        """
        self.db.execute(
            "INSERT INTO deliveries (channel, satellite, subject, body, created, status, next_attempt) "
            "VALUES (?, ?, ?, ?, ?, ?, ?)",
            (
                channel,
                satellite,
                message.subject,
                message.to_json(),
                iso(now),
                DeliveryStatus.PENDING,
                iso(now),
            ),
        )

    def due(self, now: dt.datetime) -> list[Delivery]:
        """Deliveries to try now: pending ones whose time has come, and claims whose lease ran out (a
        sender that died mid-send).

        Parameters
        ----------
        now : datetime.datetime
            Now, UTC.

        Returns
        -------
        list of Delivery
            Oldest first.
        """
        return [
            Delivery.from_row(r)
            for r in self.db.execute(
                "SELECT * FROM deliveries WHERE status IN (?, ?) AND next_attempt <= ? ORDER BY id",
                (DeliveryStatus.PENDING, DeliveryStatus.SENDING, iso(now)),
            )
        ]

    def claim(self, delivery_id: int, now: dt.datetime, lease_s: float = 600.0) -> bool:
        """Take a due delivery for sending, atomically: False when another sender has it (no double send).

        The claim holds for *lease_s*; a sender that dies leaves it to be tried again after that.

        Parameters
        ----------
        delivery_id : int
            The delivery.
        now : datetime.datetime
            Now, UTC.
        lease_s : float, optional
            How long the claim holds, s.

        Returns
        -------
        bool
            Whether this sender has it.
        """
        with self.store.transaction():
            cur = self.db.execute(
                "UPDATE deliveries SET status=?, next_attempt=? "
                "WHERE id=? AND status IN (?, ?) AND next_attempt <= ?",
                (
                    DeliveryStatus.SENDING,
                    iso(now + dt.timedelta(seconds=lease_s)),
                    delivery_id,
                    DeliveryStatus.PENDING,
                    DeliveryStatus.SENDING,
                    iso(now),
                ),
            )
            return cur.rowcount == 1

    def deliveries(self, status: DeliveryStatus | None = None) -> list[Delivery]:
        """The queued deliveries (with *status*: pending, sending, sent, failed), oldest first.

        Parameters
        ----------
        status : DeliveryStatus, optional
            Only those in this state.

        Returns
        -------
        list of Delivery
            Oldest first.
        """
        q = "SELECT * FROM deliveries" + (" WHERE status=?" if status else "") + " ORDER BY id"
        return [Delivery.from_row(r) for r in self.db.execute(q, (status,) if status else ())]

    def mark(
        self,
        delivery_id: int,
        status: DeliveryStatus,
        now: dt.datetime,
        error: str | None = None,
        retry_after_s: float = 0.0,
    ) -> None:
        """Record a delivery attempt's *status*; a retry waits *retry_after_s*.

        Parameters
        ----------
        delivery_id : int
            The delivery.
        status : DeliveryStatus
            The attempt's outcome.
        now : datetime.datetime
            Now, UTC.
        error : str, optional
            What went wrong.
        retry_after_s : float, optional
            When to try again, s from now.
        """
        with self.store.transaction():
            self.db.execute(
                "UPDATE deliveries SET status=?, attempts=attempts+1, last_error=?, next_attempt=?, sent=? "
                "WHERE id=?",
                (
                    status,
                    error,
                    iso(now + dt.timedelta(seconds=retry_after_s)),
                    iso(now) if status == DeliveryStatus.SENT else None,
                    delivery_id,
                ),
            )
