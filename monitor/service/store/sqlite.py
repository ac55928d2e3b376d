"""The embedded store: one SQLite file in WAL mode, with a schema version and forward migrations.

It holds the runs (the ledger of processed days), the per-FOR results with their flags, the granules
used with their metadata (aux file lists, software versions), the scene-selection decisions, the cost
cubes, service events, the alert state, silences and delivery queue (:mod:`monitor.service.store.alerts`), and
the
outbox of time-series points still to publish. All of the service's SQL lives in this package. A day's
results are replaced in one transaction, so a re-run never duplicates and a crash never leaves half a day.

Why one module of ~630 lines: the schema, its migrations and the reads and writes of its tables are one
idea, the file's format; split, two modules would each know the other's columns (the alert tables, which
the alerts use alone, are in :mod:`monitor.service.store.alerts`).
"""

from __future__ import annotations

import datetime as dt
import json
import os
import sqlite3
from collections.abc import Callable
from pathlib import Path
from types import TracebackType
from typing import Any, Literal

import numpy as np

from monitor.core.constants import N_FOR
from monitor.core.records import Event, ForSeries, GranuleRow, Run, SelectionRow
from monitor.core.result import MEASURED_FIELDS, AssessmentResult, DifferenceBin, ForOffset
from monitor.core.vocabulary import DONE, EventKind, RunStatus
from monitor.service.store.alerts import AlertState

UTC = dt.timezone.utc

MIGRATIONS = [
    # 1: the first schema
    """
    CREATE TABLE runs (
        id INTEGER PRIMARY KEY, satellite TEXT NOT NULL, day TEXT NOT NULL,
        started TEXT NOT NULL, finished TEXT, status TEXT NOT NULL, reason TEXT,
        n_granules INTEGER DEFAULT 0, summary TEXT);
    CREATE INDEX runs_day ON runs (satellite, day);
    CREATE TABLE results (
        satellite TEXT NOT NULL, day TEXT NOT NULL, for_index INTEGER NOT NULL, run_id INTEGER NOT NULL,
        d_alpha_urad REAL, d_beta_urad REAL, sigma_alpha_urad REAL, sigma_beta_urad REAL,
        in_track_km REAL, cross_track_km REAL, total_km REAL, sigma_in_track_km REAL,
        sigma_cross_track_km REAL, n_samples INTEGER, cost_min_k REAL, cost_zero_k REAL, flags TEXT,
        PRIMARY KEY (satellite, day, for_index));
    CREATE TABLE granules (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, granule_id TEXT NOT NULL,
        start TEXT, cris_geo TEXT, cris_sdr TEXT, viirs TEXT, n_usable INTEGER,
        software_version TEXT, algorithm_version TEXT, cris_aux TEXT, viirs_aux TEXT, viirs_software TEXT,
        PRIMARY KEY (satellite, day, granule_id));
    CREATE TABLE selection (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, granule TEXT NOT NULL,
        score_k REAL, decision TEXT NOT NULL, reason TEXT);
    CREATE INDEX selection_day ON selection (satellite, day);
    CREATE TABLE cost_cubes (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, half_steps INTEGER,
        step_urad REAL, cube BLOB, PRIMARY KEY (satellite, day));
    CREATE TABLE skipped (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, item TEXT, reason TEXT);
    CREATE TABLE events (
        id INTEGER PRIMARY KEY, time TEXT NOT NULL, kind TEXT NOT NULL, satellite TEXT, detail TEXT);
    CREATE TABLE outbox (
        id INTEGER PRIMARY KEY, target TEXT NOT NULL, satellite TEXT, day TEXT, line TEXT NOT NULL,
        created TEXT NOT NULL, attempts INTEGER DEFAULT 0, last_error TEXT);
    """,
    # 2: the daily LOS fingerprint of CrIS geolocation processing
    """
    CREATE TABLE fingerprints (
        satellite TEXT NOT NULL, day TEXT NOT NULL, computed TEXT NOT NULL, body TEXT NOT NULL,
        PRIMARY KEY (satellite, day));
    """,
    # 3: the alert tables (monitor/service/store/alerts.py), until now created by the alert state itself: IF
    # NOT
    # EXISTS keeps the rows of stores that have them; alert_meta, their own version table, goes
    """
    CREATE TABLE IF NOT EXISTS alert_state (
        fingerprint TEXT PRIMARY KEY, rule TEXT NOT NULL, satellite TEXT NOT NULL, grp TEXT, severity TEXT,
        status TEXT NOT NULL, started TEXT, last_notified TEXT, resolved TEXT, summary TEXT, lines TEXT);
    CREATE TABLE IF NOT EXISTS silences (
        id INTEGER PRIMARY KEY, rule TEXT, satellite TEXT, until TEXT NOT NULL, reason TEXT NOT NULL,
        created TEXT);
    CREATE TABLE IF NOT EXISTS deliveries (
        id INTEGER PRIMARY KEY, channel TEXT NOT NULL, satellite TEXT, subject TEXT NOT NULL,
        body TEXT NOT NULL, created TEXT NOT NULL, status TEXT NOT NULL, attempts INTEGER DEFAULT 0,
        next_attempt TEXT, last_error TEXT, sent TEXT);
    DROP TABLE IF EXISTS alert_meta;
    """,
    # 4: the CrIS-VIIRS intercalibration at each FOR's optimum, and the day's difference against the CrIS BT
    # (monitor/estimation/intercal.py); days stored before have none (NULL)
    """
    ALTER TABLE results ADD COLUMN bias_k REAL;
    ALTER TABLE results ADD COLUMN sigma_bias_k REAL;
    ALTER TABLE results ADD COLUMN gain_pct REAL;
    ALTER TABLE results ADD COLUMN sigma_gain_pct REAL;
    ALTER TABLE results ADD COLUMN curvature_k REAL;
    ALTER TABLE results ADD COLUMN sigma_curvature_k REAL;
    CREATE TABLE difference_bins (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, low_k REAL NOT NULL,
        n INTEGER, mean_k REAL, std_k REAL, PRIMARY KEY (satellite, day, low_k));
    """,
    # 5: the CrIS spatial response seen at each FOR's optimum (kernel footprint,
    # monitor/estimation/estimate.py); days
    # stored before have none (NULL)
    """
    ALTER TABLE results ADD COLUMN response_width_50_urad REAL;
    ALTER TABLE results ADD COLUMN sigma_response_width_50_urad REAL;
    ALTER TABLE results ADD COLUMN response_width_10_urad REAL;
    ALTER TABLE results ADD COLUMN sigma_response_width_10_urad REAL;
    """,
]

RESULT_FIELDS = MEASURED_FIELDS  # the results table has a column for each


def utc_now() -> dt.datetime:
    """The time now, UTC (the store's default clock)."""
    return dt.datetime.now(UTC)


def _num(v: object) -> object:
    return None if v is None or (isinstance(v, float) and not np.isfinite(v)) else v


class StoreError(RuntimeError):
    """The store file cannot be used (corrupt, empty, not a crisgeo store, too new); one line, naming it."""


class Store:
    """The SQLite store. One connection per Store; use from one thread at a time.

    A store is created only where no file exists (built under a temporary name, then renamed into place);
    an existing file that is empty, corrupt or not a crisgeo store is refused with :class:`StoreError`,
    never re-initialised: it holds the history and the alert state.
    """

    def __init__(
        self, path: str | os.PathLike[str], create: bool = True, clock: Callable[[], dt.datetime] = utc_now
    ) -> None:
        self.path = Path(path)
        self.clock = clock  # the time stamped on what is written (runs, events, the outbox)
        if not self.path.exists():
            if not create:
                raise StoreError(
                    f"{self.path}: no crisgeo store here yet (crisgeo run or the daemon creates it)"
                )
            try:
                self.path.parent.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise StoreError(f"{self.path}: cannot create its folder ({exc.strerror or exc})") from None
            self._create()
        elif self.path.stat().st_size == 0:
            raise StoreError(
                f"{self.path}: empty file, not a crisgeo store (restore it from a backup, or remove "
                f"it to start a new history)"
            )
        try:
            self.db = self._connect(self.path)
            tables = self.db.execute("SELECT COUNT(*) FROM sqlite_master").fetchone()[0]
            if 0 < len(MIGRATIONS) < self.schema_version:
                self._migrate()  # says it is newer than this program
            if self.schema_version == 0 or tables == 0:
                raise StoreError(
                    f"{self.path}: not a crisgeo store (schema version {self.schema_version}, "
                    f"{tables} tables)"
                )
            self._migrate()
        except sqlite3.DatabaseError as exc:
            raise StoreError(f"{self.path}: not a usable crisgeo store ({exc})") from None

    @staticmethod
    def _connect(path: str | os.PathLike[str]) -> sqlite3.Connection:
        db = sqlite3.connect(path, timeout=30, isolation_level=None)
        db.row_factory = sqlite3.Row
        db.execute("PRAGMA journal_mode=WAL")
        db.execute("PRAGMA synchronous=FULL")
        db.execute("PRAGMA foreign_keys=ON")
        return db

    def _create(self) -> None:
        tmp = self.path.with_name(self.path.name + ".new")
        tmp.unlink(missing_ok=True)
        self.db = self._connect(tmp)
        self._migrate()
        self.db.execute("PRAGMA journal_mode=DELETE")  # fold the WAL in before the rename
        self.db.close()
        tmp.replace(self.path)

    def close(self) -> None:
        """Close the connection."""
        self.db.close()

    def __enter__(self) -> "Store":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- schema
    @property
    def schema_version(self) -> int:
        """The schema version of the file (SQLite user_version)."""
        return self.db.execute("PRAGMA user_version").fetchone()[0]

    def _migrate(self) -> None:
        version = self.schema_version
        if version > len(MIGRATIONS):
            raise StoreError(
                f"{self.path}: schema version {version} is newer than this program "
                f"({len(MIGRATIONS)}); upgrade crisgeo"
            )
        for v in range(version, len(MIGRATIONS)):
            with self.transaction():
                for stmt in filter(str.strip, MIGRATIONS[v].split(";")):
                    self.db.execute(stmt)
                self.db.execute(f"PRAGMA user_version={v + 1}")

    def _now(self) -> str:
        return self.clock().astimezone(UTC).isoformat(timespec="seconds")

    def transaction(self) -> _Transaction:
        """A context manager: BEGIN IMMEDIATE ... COMMIT, rolled back on an exception; a file system
        without room is a :class:`StoreError` naming the file (the transaction rolled back whole)."""
        return _Transaction(self.db, self.path)

    def alert_state(self) -> AlertState:
        """The alert state, silences and delivery queue of this store."""
        return AlertState(self)

    # -- runs (the ledger)
    def begin_run(self, satellite: str, day: dt.date) -> int:
        """Open a run of *satellite* on *day* in the ledger (status running); its id."""
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
        """Close run *run_id* with *status* and *reason*."""
        with self.transaction():
            self._finish(run_id, status, reason, n_granules, summary)

    def _finish(
        self, run_id: int, status: RunStatus, reason: str | None, n_granules: int, summary: dict | None
    ) -> None:
        self.db.execute(
            "UPDATE runs SET finished=?, status=?, reason=?, n_granules=?, summary=? WHERE id=?",
            (self._now(), status, reason, n_granules, json.dumps(summary) if summary else None, run_id),
        )

    def interrupt_stale_runs(self) -> int:
        """Mark runs left 'running' by a killed process as 'interrupted'; returns how many."""
        with self.transaction():
            cur = self.db.execute(
                "UPDATE runs SET status=?, finished=?, reason='process ended during the run' WHERE status=?",
                (RunStatus.INTERRUPTED, self._now(), RunStatus.RUNNING),
            )
            return cur.rowcount

    def done_days(self, satellite: str, no_data_final_before: dt.date | None = None) -> set:
        """Days with a completed run: results stored, or no data for good. A plain ``no_data`` day counts
        as done only before *no_data_final_before* (None: always); later ones are tried again."""
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
        """The latest run of each satellite."""
        return [
            Run.from_row(r)
            for r in self.db.execute(
                "SELECT r.* FROM runs r JOIN (SELECT satellite, MAX(id) AS id FROM runs GROUP BY satellite) "
                "m ON r.id = m.id ORDER BY r.satellite"
            )
        ]

    def run_counts(self) -> dict:
        """{(satellite, status): number of runs} over the whole ledger."""
        return {
            (r[0], r[1]): r[2]
            for r in self.db.execute(
                "SELECT satellite, status, COUNT(*) FROM runs GROUP BY satellite, status"
            )
        }

    def first_runs(self) -> dict:
        """{satellite: start time (aware UTC datetime) of its first run}: since when it is monitored."""
        return {
            r[0]: dt.datetime.fromisoformat(r[1])
            for r in self.db.execute("SELECT satellite, MIN(started) FROM runs GROUP BY satellite")
        }

    def last_success(self) -> dict:
        """{satellite: finish time (aware UTC datetime) of its latest ok run}."""
        return {
            r[0]: dt.datetime.fromisoformat(r[1])
            for r in self.db.execute(
                "SELECT satellite, MAX(finished) FROM runs WHERE status=? AND finished IS NOT NULL GROUP "
                "BY satellite",
                (RunStatus.OK,),
            )
        }

    def outbox_sizes(self) -> dict:
        """{target: points waiting}."""
        return dict(self.db.execute("SELECT target, COUNT(*) FROM outbox GROUP BY target").fetchall())

    def runs(self, satellite: str | None = None) -> list[Run]:
        """The runs (of *satellite*), oldest first."""
        q = "SELECT * FROM runs" + (" WHERE satellite=?" if satellite else "") + " ORDER BY id"
        return [Run.from_row(r) for r in self.db.execute(q, (satellite,) if satellite else ())]

    # -- results
    def save_day(
        self,
        run_id: int,
        satellite: str,
        day: dt.date,
        result: AssessmentResult,
        selection: list,
        outbox_lines: dict,
    ) -> None:
        """Replace the day's results, granules, selection and cube, queue its points, close the run, in one
        transaction."""
        d = day.isoformat()
        with self.transaction():
            for table in ("results", "granules", "selection", "cost_cubes", "skipped", "difference_bins"):
                self.db.execute(f"DELETE FROM {table} WHERE satellite=? AND day=?", (satellite, d))
            for f in result.fors:
                self.db.execute(
                    f"INSERT INTO results (satellite, day, for_index, run_id, {', '.join(RESULT_FIELDS)}, "
                    "flags) "
                    f"VALUES (?, ?, ?, ?, {', '.join('?' * len(RESULT_FIELDS))}, ?)",
                    (
                        satellite,
                        d,
                        f.for_index,
                        run_id,
                        *[_num(getattr(f, k)) for k in RESULT_FIELDS],
                        json.dumps(list(f.flags)),
                    ),
                )
            for g in result.granules:
                cm, vm = g.cris_meta, g.viirs_meta
                self.db.execute(
                    "INSERT OR REPLACE INTO granules VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (
                        satellite,
                        d,
                        run_id,
                        g.granule_id,
                        g.start,
                        g.cris_geo,
                        g.cris_sdr,
                        json.dumps(g.viirs),
                        g.n_usable,
                        cm.get("software_version"),
                        cm.get("algorithm_version"),
                        json.dumps(cm.get("aux_files", [])),
                        json.dumps(vm.get("aux_files", [])),
                        vm.get("software_version"),
                    ),
                )
            for s in selection:
                self.db.execute(
                    "INSERT INTO selection VALUES (?, ?, ?, ?, ?, ?, ?)",
                    (
                        satellite,
                        d,
                        run_id,
                        s.granule,
                        _num(s.score_k),
                        s.decision,
                        s.reason,
                    ),
                )
            for b in result.difference_bins:
                self.db.execute(
                    "INSERT INTO difference_bins VALUES (?, ?, ?, ?, ?, ?, ?)",
                    (satellite, d, run_id, b.low_k, b.n, _num(b.mean_k), _num(b.std_k)),
                )
            for s in result.skipped:
                self.db.execute(
                    "INSERT INTO skipped VALUES (?, ?, ?, ?, ?)",
                    (satellite, d, run_id, s.item, s.reason),
                )
            if result.cost_cube_k is not None:
                self.db.execute(
                    "INSERT INTO cost_cubes VALUES (?, ?, ?, ?, ?, ?)",
                    (
                        satellite,
                        d,
                        run_id,
                        result.half_steps,
                        result.step_urad,
                        np.asarray(result.cost_cube_k, np.float32).tobytes(),
                    ),
                )
            self.db.execute("DELETE FROM outbox WHERE satellite=? AND day=?", (satellite, d))
            for target, lines in outbox_lines.items():
                for line in lines:
                    self.db.execute(
                        "INSERT INTO outbox (target, satellite, day, line, created) VALUES (?, ?, ?, ?, ?)",
                        (target, satellite, d, line, self._now()),
                    )
            self._finish(
                run_id,
                RunStatus.OK,
                None,
                len(result.granules),
                {
                    "reliable_fors": sum(f.reliable for f in result.fors),
                    "max_total_km": max(
                        (f.total_km for f in result.fors if np.isfinite(f.total_km)), default=None
                    ),
                },
            )

    def day_result(self, satellite: str, day: dt.date) -> list[ForOffset]:
        """The per-FOR offsets stored for *satellite* on *day*."""
        rows = self.db.execute(
            "SELECT * FROM results WHERE satellite=? AND day=? ORDER BY for_index",
            (satellite, day.isoformat()),
        ).fetchall()
        out = []
        for r in rows:
            kw: dict[str, Any] = {k: (float("nan") if r[k] is None else r[k]) for k in RESULT_FIELDS}
            kw["n_samples"] = int(r["n_samples"] or 0)
            out.append(ForOffset(for_index=r["for_index"], flags=tuple(json.loads(r["flags"])), **kw))
        return out

    def difference_bins(self, satellite: str, day: dt.date) -> list[DifferenceBin]:
        """CrIS minus VIIRS against the CrIS BT at the optimum on *satellite*'s *day* (Figure 15)."""
        rows = self.db.execute(
            "SELECT low_k, n, mean_k, std_k FROM difference_bins WHERE satellite=? AND day=? ORDER BY low_k",
            (satellite, day.isoformat()),
        ).fetchall()
        return [
            DifferenceBin(
                r["low_k"], r["n"], *(float("nan") if v is None else v for v in (r["mean_k"], r["std_k"]))
            )
            for r in rows
        ]

    def latest_day(self, satellite: str) -> dt.date | None:
        """The latest day with results for *satellite*, or None."""
        r = self.db.execute("SELECT MAX(day) FROM results WHERE satellite=?", (satellite,)).fetchone()[0]
        return dt.date.fromisoformat(r) if r else None

    def series(self, satellite: str, since: dt.date | None = None, until: dt.date | None = None) -> ForSeries:
        """The per-FOR results of *satellite* from *since* to *until* (both included) as arrays."""
        q = "SELECT * FROM results WHERE satellite=?"
        args = [satellite]
        if since:
            q += " AND day >= ?"
            args.append(since.isoformat())
        if until:
            q += " AND day <= ?"
            args.append(until.isoformat())
        rows = self.db.execute(q + " ORDER BY day, for_index", args).fetchall()
        days = sorted({r["day"] for r in rows})
        index = {d: i for i, d in enumerate(days)}
        shape = (len(days), N_FOR)
        values = {k: np.full(shape, np.nan) for k in RESULT_FIELDS if k != "n_samples"}
        values["n_samples"] = np.zeros(shape, np.int64)
        flags = np.empty(shape, object)
        flags.fill(())
        stored = np.zeros(shape, bool)
        for r in rows:
            at = (index[r["day"]], r["for_index"] - 1)
            for k in values:
                if r[k] is not None:
                    values[k][at] = r[k]
            flags[at] = tuple(json.loads(r["flags"] or "[]"))
            stored[at] = True
        return ForSeries([dt.date.fromisoformat(d) for d in days], values, flags, stored)

    def granules(self, satellite: str, day: dt.date | None = None) -> list[GranuleRow]:
        """The granules assessed for *satellite* (on *day*), with their metadata."""
        q = (
            "SELECT * FROM granules WHERE satellite=?"
            + (" AND day=?" if day else "")
            + " ORDER BY day, start"
        )
        args = (satellite, day.isoformat()) if day else (satellite,)
        return [GranuleRow.from_row(r) for r in self.db.execute(q, args)]

    def selection(self, satellite: str, day: dt.date) -> list[SelectionRow]:
        """The scene-selection decisions of *satellite* on *day*."""
        return [
            SelectionRow.from_row(r)
            for r in self.db.execute(
                "SELECT * FROM selection WHERE satellite=? AND day=?", (satellite, day.isoformat())
            )
        ]

    def cost_cube(self, satellite: str, day: dt.date) -> tuple[np.ndarray, float] | None:
        """(cube_k (30, 2n+1, 2n+1), step_urad) of the day's assessment, or None."""
        r = self.db.execute(
            "SELECT half_steps, step_urad, cube FROM cost_cubes WHERE satellite=? AND day=?",
            (satellite, day.isoformat()),
        ).fetchone()
        if r is None:
            return None
        m = 2 * r["half_steps"] + 1
        return np.frombuffer(r["cube"], np.float32).reshape(-1, m, m), r["step_urad"]

    # -- fingerprints
    def save_fingerprint(self, satellite: str, day: dt.date, body: dict) -> None:
        """Store the LOS fingerprint of *satellite* on *day* (replacing one computed before)."""
        with self.transaction():
            self.db.execute(
                "INSERT OR REPLACE INTO fingerprints VALUES (?, ?, ?, ?)",
                (satellite, day.isoformat(), self._now(), json.dumps(body)),
            )

    def fingerprint(self, satellite: str, before: dt.date) -> tuple[dt.date, dict] | None:
        """(day, body) of the latest fingerprint strictly before *before*, or None."""
        r = self.db.execute(
            "SELECT day, body FROM fingerprints WHERE satellite=? AND day < ? ORDER BY day DESC LIMIT 1",
            (satellite, before.isoformat()),
        ).fetchone()
        return None if r is None else (dt.date.fromisoformat(r["day"]), json.loads(r["body"]))

    # -- events (failures, misses: the alerting layer reads them)
    def add_event(self, kind: "EventKind", satellite: str | None, detail: dict) -> None:
        """Record an event; *detail* is stored as JSON."""
        with self.transaction():
            self.db.execute(
                "INSERT INTO events (time, kind, satellite, detail) VALUES (?, ?, ?, ?)",
                (self._now(), EventKind(kind).value, satellite, json.dumps(detail)),
            )

    def events(self, kind: "EventKind | None" = None) -> list["Event"]:
        """The events (of *kind*), oldest first."""
        q = "SELECT * FROM events" + (" WHERE kind=?" if kind else "") + " ORDER BY id"
        return [Event.from_row(r) for r in self.db.execute(q, (EventKind(kind).value,) if kind else ())]

    # -- outbox
    def queue_lines(self, target: str, satellite: str | None, lines: list) -> None:
        """Queue points not tied to a day's results (e.g. change annotations)."""
        with self.transaction():
            for line in lines:
                self.db.execute(
                    "INSERT INTO outbox (target, satellite, day, line, created) VALUES (?, ?, NULL, ?, ?)",
                    (target, satellite, line, self._now()),
                )

    def outbox(self, target: str, limit: int = 5000) -> list:
        """Up to *limit* points waiting for *target*, oldest first."""
        return [
            dict(r)
            for r in self.db.execute(
                "SELECT id, line FROM outbox WHERE target=? ORDER BY id LIMIT ?", (target, limit)
            )
        ]

    def outbox_size(self, target: str | None = None) -> int:
        """The number of points waiting (for *target*)."""
        q = "SELECT COUNT(*) FROM outbox" + (" WHERE target=?" if target else "")
        return self.db.execute(q, (target,) if target else ()).fetchone()[0]

    def outbox_delivered(self, ids: list) -> None:
        """Remove delivered points."""
        with self.transaction():
            self.db.executemany("DELETE FROM outbox WHERE id=?", [(i,) for i in ids])

    def outbox_failed(self, ids: list, error: str) -> None:
        """Count a failed attempt and its error on the points."""
        with self.transaction():
            self.db.executemany(
                "UPDATE outbox SET attempts = attempts + 1, last_error=? WHERE id=?",
                [(error[:500], i) for i in ids],
            )


class _Transaction:
    def __init__(self, db: sqlite3.Connection, path: Path) -> None:
        self.db = db
        self.path = path
        self.depth_outer = False

    def __enter__(self) -> sqlite3.Connection:
        self.depth_outer = not self.db.in_transaction
        if self.depth_outer:
            self.db.execute("BEGIN IMMEDIATE")
        return self.db

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> Literal[False]:
        if not self.depth_outer:
            return False
        try:
            if exc_type is None:
                self.db.execute("COMMIT")
                return False
        except sqlite3.OperationalError as failed:
            exc = failed
        if self.db.in_transaction:
            self.db.execute("ROLLBACK")
        if isinstance(exc, sqlite3.OperationalError) and exc.sqlite_errorcode == sqlite3.SQLITE_FULL:
            raise StoreError(f"{self.path}: no room left on its file system ({exc}); nothing was written")
        if exc_type is None and exc is not None:  # a COMMIT that failed otherwise
            raise exc
        return False
