"""The outbox: time-series lines still to publish, per target, delivered or retried by the publisher."""

from __future__ import annotations

import sqlite3
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import TYPE_CHECKING


@dataclass(frozen=True)
class QueuedLines:
    """Time-series lines for one publishing *target* (:func:`monitor.service.outputs.timeseries.target_name`),
    queued with the day that produced them."""

    target: str
    lines: list[str]


class Outbox:
    """The outbox of a store (a part of :class:`monitor.service.store.sqlite.Store`, over its file)."""

    db: sqlite3.Connection
    if TYPE_CHECKING:  # of the Database the parts are put together with

        def transaction(self) -> AbstractContextManager[sqlite3.Connection]: ...
        def _now(self) -> str: ...

    # -- outbox
    def queue_lines(self, target: str, satellite: str | None, lines: list) -> None:
        """Queue points not tied to a day's results (e.g. change annotations).

        Parameters
        ----------
        target : str
            The time-series database (its name).
        satellite : str or None
            The satellite's short name; None: every one.
        lines : list
            Line-protocol points.
        """
        with self.transaction():
            for line in lines:
                self.db.execute(
                    "INSERT INTO outbox (target, satellite, day, line, created) VALUES (?, ?, NULL, ?, ?)",
                    (target, satellite, line, self._now()),
                )

    def outbox(self, target: str, limit: int = 5000) -> list:
        """Up to *limit* points waiting for *target*, oldest first.

        Parameters
        ----------
        target : str
            The time-series database.
        limit : int, optional
            At most this many.

        Returns
        -------
        list
            Dicts of ``id`` and ``line``.
        """
        return [
            dict(r)
            for r in self.db.execute(
                "SELECT id, line FROM outbox WHERE target=? ORDER BY id LIMIT ?", (target, limit)
            )
        ]

    def outbox_errors(self, target: str) -> list[str]:
        """The last error of each point waiting for *target* (empty where it was never tried), oldest first.

        Parameters
        ----------
        target : str
            The time-series database.

        Returns
        -------
        list of str
            One per point waiting.
        """
        rows = self.db.execute("SELECT last_error FROM outbox WHERE target=? ORDER BY id", (target,))
        return [r[0] or "" for r in rows]

    def outbox_size(self, target: str | None = None) -> int:
        """The number of points waiting (for *target*).

        Parameters
        ----------
        target : str, optional
            Only this target.

        Returns
        -------
        int
            Points waiting.
        """
        q = "SELECT COUNT(*) FROM outbox" + (" WHERE target=?" if target else "")
        return self.db.execute(q, (target,) if target else ()).fetchone()[0]

    def outbox_delivered(self, ids: list) -> None:
        """Remove delivered points.

        Parameters
        ----------
        ids : list
            The points' ids.
        """
        with self.transaction():
            self.db.executemany("DELETE FROM outbox WHERE id=?", [(i,) for i in ids])

    def outbox_failed(self, ids: list, error: str) -> None:
        """Count a failed attempt and its error on the points.

        Parameters
        ----------
        ids : list
            The points' ids.
        error : str
            What went wrong.
        """
        with self.transaction():
            self.db.executemany(
                "UPDATE outbox SET attempts = attempts + 1, last_error=? WHERE id=?",
                [(error[:500], i) for i in ids],
            )

    def outbox_sizes(self) -> dict:
        """{target: points waiting}.

        Returns
        -------
        dict
            {target: points waiting}.
        """
        return dict(self.db.execute("SELECT target, COUNT(*) FROM outbox GROUP BY target").fetchall())
