"""The run ledger: one row per satellite-day run (running, ok, no data, failed, interrupted) and the
service's events."""

from __future__ import annotations

import datetime as dt
import json
import sqlite3
from contextlib import AbstractContextManager
from typing import TYPE_CHECKING

from monitor.core.result import DayPrecision
from monitor.core.vocabulary import DONE, EventKind, RunStatus
from monitor.history.records import Event, Run


class RunLedger:
    """The ledger of runs and the service events of a store (a part of
    :class:`monitor.service.store.sqlite.Store`, over its file)."""

    db: sqlite3.Connection
    if TYPE_CHECKING:  # of the Database the parts are put together with

        def transaction(self) -> AbstractContextManager[sqlite3.Connection]: ...
        def _now(self) -> str: ...

    # -- runs (the ledger)
    def begin_run(self, satellite: str, day: dt.date) -> int:
        """Open a run of *satellite* on *day* in the ledger (status running); its id.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.

        Returns
        -------
        int
            The run's id.
        """
        with self.transaction():
            cur = self.db.execute(
                "INSERT INTO runs (satellite, day, started, status) VALUES (?, ?, ?, ?)",
                (satellite, day.isoformat(), self._now(), RunStatus.RUNNING),
            )
            return int(cur.lastrowid or 0)  # (set by an INSERT)

    def finish_run(
        self,
        run_id: int,
        status: RunStatus,
        reason: str | None = None,
        n_granules: int = 0,
        summary: dict | None = None,
    ) -> None:
        """Close run *run_id* with *status* and *reason*.

        Parameters
        ----------
        run_id : int
            The run.
        status : RunStatus
            Its outcome.
        reason : str, optional
            Why, when not ok.
        n_granules : int, optional
            Granules assessed.
        summary : dict, optional
            The run's summary (stages, precision, counts).
        """
        with self.transaction():
            self._finish(run_id, status, reason, n_granules, summary)

    def _finish(
        self, run_id: int, status: RunStatus, reason: str | None, n_granules: int, summary: dict | None
    ) -> None:
        self.db.execute(
            "UPDATE runs SET finished=?, status=?, reason=?, n_granules=?, summary=? WHERE id=?",
            (self._now(), status, reason, n_granules, json.dumps(summary) if summary else None, run_id),
        )

    def record_stages(self, run_id: int, stages: dict[str, float]) -> None:
        """Keep the wall seconds of run *run_id*'s stages with it (``stages`` in its summary), so that
        ``/metrics`` shows the latest run's after a restart too.

        Parameters
        ----------
        run_id : int
            The run.
        stages : dict of str to float
            Wall seconds per stage.
        """
        with self.transaction():
            row = self.db.execute("SELECT summary FROM runs WHERE id=?", (run_id,)).fetchone()
            doc = json.loads(row["summary"]) if row is not None and row["summary"] else {}
            doc["stages"] = {k: round(float(v), 3) for k, v in stages.items()}
            self.db.execute("UPDATE runs SET summary=? WHERE id=?", (json.dumps(doc), run_id))

    def latest_stages(self) -> dict[str, dict[str, float]]:
        """Per satellite the stages' wall seconds of its latest run that recorded them.

        Returns
        -------
        dict
            {satellite: {stage: seconds}}.
        """
        out: dict[str, dict[str, float]] = {}
        for r in self.db.execute(
            "SELECT satellite, summary FROM runs WHERE summary LIKE '%\"stages\"%' ORDER BY id"
        ):
            out[r["satellite"]] = json.loads(r["summary"])["stages"]
        return out

    def interrupt_stale_runs(self) -> int:
        """Mark runs left 'running' by a killed process as 'interrupted'; returns how many.

        Returns
        -------
        int
            How many were marked.
        """
        with self.transaction():
            cur = self.db.execute(
                "UPDATE runs SET status=?, finished=?, reason='process ended during the run' WHERE status=?",
                (RunStatus.INTERRUPTED, self._now(), RunStatus.RUNNING),
            )
            return cur.rowcount

    def done_days(self, satellite: str, no_data_final_before: dt.date | None = None) -> set:
        """Days with a completed run: results stored, or no data for good. A plain ``no_data`` day counts
        as done only before *no_data_final_before* (None: always); later ones are tried again.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        no_data_final_before : datetime.date, optional
            A ``no_data`` day counts as done only before it (None: always).

        Returns
        -------
        set of datetime.date
            The days done.
        """
        rows = self.db.execute(
            "SELECT DISTINCT day, status FROM runs WHERE satellite=? AND status IN (?, ?, ?)",
            (satellite, *DONE),
        )
        out = set()
        for day, status in rows:
            d = dt.date.fromisoformat(day)
            if status != RunStatus.NO_DATA or no_data_final_before is None or d < no_data_final_before:
                out.add(d)
        return out

    def last_runs(self) -> list[Run]:
        """The latest run of each satellite.

        Returns
        -------
        list of Run
            One per satellite.
        """
        return [
            Run.from_row(r)
            for r in self.db.execute(
                "SELECT r.* FROM runs r JOIN (SELECT satellite, MAX(id) AS id FROM runs GROUP BY satellite) "
                "m ON r.id = m.id ORDER BY r.satellite"
            )
        ]

    def latest_precision(self, satellite: str) -> DayPrecision | None:
        """How far *satellite*'s latest ok run went for its precision (None: no such run, or one from
        before the batches).

        Parameters
        ----------
        satellite : str
            The satellite's short name.

        Returns
        -------
        DayPrecision or None
            None without such a run.
        """
        row = self.db.execute(
            "SELECT summary FROM runs WHERE satellite=? AND status=? ORDER BY id DESC LIMIT 1",
            (satellite, RunStatus.OK),
        ).fetchone()
        return None if row is None else DayPrecision.from_summary(row[0])

    def run_counts(self) -> dict:
        """{(satellite, status): number of runs} over the whole ledger.

        Returns
        -------
        dict
            {(satellite, status): runs}.
        """
        return {
            (r[0], r[1]): r[2]
            for r in self.db.execute(
                "SELECT satellite, status, COUNT(*) FROM runs GROUP BY satellite, status"
            )
        }

    def first_runs(self) -> dict:
        """{satellite: start time (aware UTC datetime) of its first run}: since when it is monitored.

        Returns
        -------
        dict
            {satellite: aware UTC datetime}.
        """
        return {
            r[0]: dt.datetime.fromisoformat(r[1])
            for r in self.db.execute("SELECT satellite, MIN(started) FROM runs GROUP BY satellite")
        }

    def last_success(self) -> dict:
        """{satellite: finish time (aware UTC datetime) of its latest ok run}.

        Returns
        -------
        dict
            {satellite: aware UTC datetime}.
        """
        return {
            r[0]: dt.datetime.fromisoformat(r[1])
            for r in self.db.execute(
                "SELECT satellite, MAX(finished) FROM runs WHERE status=? AND finished IS NOT NULL GROUP "
                "BY satellite",
                (RunStatus.OK,),
            )
        }

    def runs(self, satellite: str | None = None) -> list[Run]:
        """The runs (of *satellite*), oldest first.

        Parameters
        ----------
        satellite : str, optional
            Only this satellite.

        Returns
        -------
        list of Run
            Oldest first.
        """
        q = "SELECT * FROM runs" + (" WHERE satellite=?" if satellite else "") + " ORDER BY id"
        return [Run.from_row(r) for r in self.db.execute(q, (satellite,) if satellite else ())]

    def runs_since_success(self, satellite: str) -> list[Run]:
        """The runs of *satellite* from its latest successful one (status ok) on, oldest first; all of them
        when none succeeded. What the stale and failure rules read, however long the history.

        Parameters
        ----------
        satellite : str
            The satellite's short name.

        Returns
        -------
        list of Run
            Oldest first.
        """
        q = (
            "SELECT * FROM runs WHERE satellite=? AND id >= "
            "COALESCE((SELECT MAX(id) FROM runs WHERE satellite=? AND status=?), 0) ORDER BY id"
        )
        return [Run.from_row(r) for r in self.db.execute(q, (satellite, satellite, RunStatus.OK))]

    # -- events (failures, misses: the alerting layer reads them)
    def add_event(self, kind: "EventKind", satellite: str | None, detail: dict) -> None:
        """Record an event; *detail* is stored as JSON.

        Parameters
        ----------
        kind : EventKind
            What it records.
        satellite : str or None
            The satellite's short name; None: every one.
        detail : dict
            Stored as JSON.
        """
        with self.transaction():
            self.db.execute(
                "INSERT INTO events (time, kind, satellite, detail) VALUES (?, ?, ?, ?)",
                (self._now(), EventKind(kind).value, satellite, json.dumps(detail)),
            )

    def events(self, kind: "EventKind | None" = None) -> list["Event"]:
        """The events (of *kind*), oldest first.

        Parameters
        ----------
        kind : EventKind, optional
            Only this kind.

        Returns
        -------
        list of Event
            Oldest first.
        """
        q = "SELECT * FROM events" + (" WHERE kind=?" if kind else "") + " ORDER BY id"
        return [Event.from_row(r) for r in self.db.execute(q, (EventKind(kind).value,) if kind else ())]
