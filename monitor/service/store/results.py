"""A day's results: the per-FOR offsets and flags (a column per measured field), the calibration
difference bins, the granules used with their metadata, the scene selection, the cost cube, the LOS
fingerprint. A day is replaced in one transaction: a re-run never duplicates, a crash never leaves half a
day."""

from __future__ import annotations

import datetime as dt
import json
import sqlite3
from collections.abc import Sequence
from contextlib import AbstractContextManager
from typing import TYPE_CHECKING

import numpy as np

from monitor.core.constants import N_FOR
from monitor.core.result import (
    MEASURED_FIELDS,
    AssessmentResult,
    DayPrecision,
    DifferenceBin,
    DifferenceMap,
    ForOffset,
    RadiometryBin,
    SceneDecision,
)
from monitor.core.vocabulary import RunStatus
from monitor.history.records import ForSeries, GranuleRow, SelectionRow
from monitor.service.store.outbox import QueuedLines

RESULT_FIELDS = MEASURED_FIELDS  # the results table has a column for each


def _num(v: object) -> object:
    return None if v is None or (isinstance(v, float) and not np.isfinite(v)) else v


class Results:
    """The per-day results of a store (a part of :class:`monitor.service.store.sqlite.Store`, over its file;
    a day's results close its run in the ledger, in one transaction)."""

    db: sqlite3.Connection
    if TYPE_CHECKING:  # of the Database and the RunLedger the parts are put together with

        def transaction(self) -> AbstractContextManager[sqlite3.Connection]: ...
        def _now(self) -> str: ...
        def _finish(
            self, run_id: int, status: RunStatus, reason: str | None, n_granules: int, summary: dict | None
        ) -> None: ...

    # -- results
    def save_day(
        self,
        run_id: int,
        satellite: str,
        day: dt.date,
        result: AssessmentResult,
        selection: Sequence[SceneDecision] = (),
        queued: Sequence[QueuedLines] = (),
        precision: DayPrecision | None = None,
    ) -> None:
        """Replace the day's results, granules, scene *selection* and cube, queue its time-series lines
        (*queued*, derived by the outputs from *result*), close the run (its summary: reliable FORs, the
        worst error, the *precision* reached), in one transaction.

        Parameters
        ----------
        run_id : int
            The run.
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.
        result : AssessmentResult
            The day's result.
        selection : sequence of SceneDecision
            The scene decisions.
        queued : sequence of QueuedLines
            Time-series lines per target.
        precision : DayPrecision, optional
            How far the day went.
        """
        d = day.isoformat()
        with self.transaction():
            for table in (
                "results", "granules", "selection", "cost_cubes", "skipped", "difference_bins",
                "radiometry_bins", "difference_maps",
            ):  # fmt: skip
                self.db.execute(f"DELETE FROM {table} WHERE satellite=? AND day=?", (satellite, d))
            # the noise fitted on days that include this one is fitted anew when next needed
            self.db.execute("DELETE FROM noise_fits WHERE satellite=? AND before > ?", (satellite, d))
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
            for c in selection:
                self.db.execute(
                    "INSERT INTO selection VALUES (?, ?, ?, ?, ?, ?, ?)",
                    (satellite, d, run_id, c.granule, _num(c.score_k), c.decision, c.reason),
                )
            for b in result.difference_bins:
                self.db.execute(
                    "INSERT INTO difference_bins VALUES (?, ?, ?, ?, ?, ?, ?)",
                    (satellite, d, run_id, b.low_k, b.n, _num(b.mean_k), _num(b.std_k)),
                )
            for r in result.radiometry:
                self.db.execute(
                    "INSERT INTO radiometry_bins VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
                    (satellite, d, run_id, r.band, str(r.by), r.key, r.n, _num(r.mean_k), _num(r.sigma_k)),
                )
            for m in result.difference_maps:
                self.db.execute(
                    "INSERT INTO difference_maps VALUES (?, ?, ?, ?, ?)",
                    (satellite, d, run_id, m.band, json.dumps(m.to_dict())),
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
            for q in queued:
                for line in q.lines:
                    self.db.execute(
                        "INSERT INTO outbox (target, satellite, day, line, created) VALUES (?, ?, ?, ?, ?)",
                        (q.target, satellite, d, line, self._now()),
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
                    **({"precision": precision.to_dict()} if precision is not None else {}),
                },
            )

    def day_result(self, satellite: str, day: dt.date) -> list[ForOffset]:
        """The per-FOR offsets stored for *satellite* on *day*.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.

        Returns
        -------
        list of ForOffset
            In FOR order.
        """
        rows = self.db.execute(
            "SELECT * FROM results WHERE satellite=? AND day=? ORDER BY for_index",
            (satellite, day.isoformat()),
        ).fetchall()
        return [
            ForOffset.from_dict(
                {**{k: r[k] for k in RESULT_FIELDS}, "for": r["for_index"], "flags": json.loads(r["flags"])}
            )
            for r in rows
        ]

    def difference_bins(self, satellite: str, day: dt.date) -> list[DifferenceBin]:
        """CrIS minus VIIRS against the CrIS BT at the optimum on *satellite*'s *day* (Figure 15).

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.

        Returns
        -------
        list of DifferenceBin
            The bins.
        """
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

    def radiometry_bins(self, satellite: str, day: dt.date) -> list[RadiometryBin]:
        """CrIS minus VIIRS per band, binned by FOV, scene temperature and node, on *satellite*'s *day*.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.

        Returns
        -------
        list of RadiometryBin
            The bins, by band and binning.
        """
        rows = self.db.execute(
            "SELECT * FROM radiometry_bins WHERE satellite=? AND day=? ORDER BY band, binned_by, rowid",
            (satellite, day.isoformat()),
        ).fetchall()
        return [RadiometryBin.from_dict({**dict(r), "by": r["binned_by"]}) for r in rows]

    def difference_maps(self, satellite: str, day: dt.date) -> list[DifferenceMap]:
        """Every FOV's CrIS minus VIIRS of one granule per band on *satellite*'s *day*.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.

        Returns
        -------
        list of DifferenceMap
            One per band compared.
        """
        rows = self.db.execute(
            "SELECT body FROM difference_maps WHERE satellite=? AND day=? ORDER BY rowid",
            (satellite, day.isoformat()),
        ).fetchall()
        return [DifferenceMap.from_dict(json.loads(r["body"])) for r in rows]

    def latest_day(self, satellite: str) -> dt.date | None:
        """The latest day with results for *satellite*, or None.

        Parameters
        ----------
        satellite : str
            The satellite's short name.

        Returns
        -------
        datetime.date or None
            The day.
        """
        r = self.db.execute("SELECT MAX(day) FROM results WHERE satellite=?", (satellite,)).fetchone()[0]
        return dt.date.fromisoformat(r) if r else None

    def series(
        self,
        satellite: str,
        since: dt.date | None = None,
        until: dt.date | None = None,
        fields: Sequence[str] | None = None,
    ) -> ForSeries:
        """The per-FOR results of *satellite* from *since* to *until* (both included) as arrays.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        since, until : datetime.date, optional
            The period, inclusive; None: open.
        fields : sequence of str, optional
            The measured fields read (:data:`RESULT_FIELDS`); all by default.

        Returns
        -------
        ForSeries
            Days x FORs arrays of the fields read, with the flags.
        """
        read = list(RESULT_FIELDS) if fields is None else [k for k in RESULT_FIELDS if k in set(fields)]
        unknown = sorted(set(fields or ()) - set(RESULT_FIELDS))
        if unknown:
            raise ValueError(f"series: no measured field {', '.join(unknown)}")
        q = f"SELECT day, for_index, flags, {', '.join(read)} FROM results WHERE satellite=?"
        args = [satellite]
        if since:
            q += " AND day >= ?"
            args.append(since.isoformat())
        if until:
            q += " AND day <= ?"
            args.append(until.isoformat())
        rows = self.db.execute(q + " ORDER BY day, for_index", args).fetchall()
        columns = list(zip(*rows, strict=True)) if rows else [()] * (3 + len(read))
        days = sorted(set(columns[0]))
        index = {d: i for i, d in enumerate(days)}
        at = (np.array([index[d] for d in columns[0]], int), np.array(columns[1], int) - 1)
        shape = (len(days), N_FOR)
        values: dict[str, np.ndarray] = {}
        for name, column in zip(read, columns[3:], strict=True):
            values[name] = np.full(shape, np.nan)
            values[name][at] = np.array(column, float)  # NULL (None) is NaN
        if "n_samples" in values:  # a count: 0 where nothing is stored
            values["n_samples"] = np.nan_to_num(values["n_samples"]).astype(np.int64)
        flags = np.empty(shape, object)
        flags.fill(())
        parsed: dict[str | None, tuple] = {}  # a day's flags repeat: each text parsed once
        for text in set(columns[2]):
            parsed[text] = tuple(json.loads(text or "[]"))
        flags[at] = np.fromiter((parsed[t] for t in columns[2]), object, count=len(rows))
        stored = np.zeros(shape, bool)
        stored[at] = True
        return ForSeries([dt.date.fromisoformat(d) for d in days], values, flags, stored)

    def noise_fit(self, satellite: str, quantity: str, before: dt.date) -> dict | None:
        """The jump rule's noise of *quantity* fitted on every day of *satellite* before *before*, as kept
        (:meth:`keep_noise_fit`); None when none is kept, or a day before *before* was stored since.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        quantity : str
            The quantity watched (its rule's name).
        before : datetime.date
            The fit covers the days before this one.

        Returns
        -------
        dict or None
            The fit as kept.
        """
        r = self.db.execute(
            "SELECT body FROM noise_fits WHERE satellite=? AND quantity=? AND before=?",
            (satellite, quantity, before.isoformat()),
        ).fetchone()
        return json.loads(r["body"]) if r else None

    def noise_fits(self, satellite: str, quantity: str) -> dict[dt.date, dict]:
        """Every noise fit of *quantity* kept for *satellite*, by the day it covers the days before.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        quantity : str
            The quantity watched (its rule's name).

        Returns
        -------
        dict
            ``before`` to the fit as kept.
        """
        rows = self.db.execute(
            "SELECT before, body FROM noise_fits WHERE satellite=? AND quantity=? ORDER BY before",
            (satellite, quantity),
        )
        return {dt.date.fromisoformat(r["before"]): json.loads(r["body"]) for r in rows}

    def keep_noise_fit(self, satellite: str, quantity: str, before: dt.date, body: dict) -> None:
        """Keep the noise of *quantity* fitted on every day of *satellite* before *before*; storing a day
        before *before* drops it (:meth:`save_day`).

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        quantity : str
            The quantity watched (its rule's name).
        before : datetime.date
            The fit covers the days before this one.
        body : dict
            The fit, JSON-serialisable.
        """
        with self.transaction():
            self.db.execute(
                "INSERT OR REPLACE INTO noise_fits VALUES (?, ?, ?, ?)",
                (satellite, quantity, before.isoformat(), json.dumps(body)),
            )

    def granules(
        self, satellite: str, day: dt.date | None = None, since: dt.date | None = None
    ) -> list[GranuleRow]:
        """The granules assessed for *satellite* (on *day*, or from *since* on), with their metadata.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date, optional
            Only this day.
        since : datetime.date, optional
            Only the days from this one on.

        Returns
        -------
        list of GranuleRow
            The granules.
        """
        q, args = "SELECT * FROM granules WHERE satellite=?", [satellite]
        for cond, value in ((" AND day=?", day), (" AND day>=?", since)):
            if value is not None:
                q += cond
                args.append(value.isoformat())
        return [GranuleRow.from_row(r) for r in self.db.execute(q + " ORDER BY day, start", args)]

    def selection(self, satellite: str, day: dt.date) -> list[SelectionRow]:
        """The scene-selection decisions of *satellite* on *day*.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.

        Returns
        -------
        list of SelectionRow
            The decisions.
        """
        return [
            SelectionRow.from_row(r)
            for r in self.db.execute(
                "SELECT * FROM selection WHERE satellite=? AND day=?", (satellite, day.isoformat())
            )
        ]

    def cost_cube(self, satellite: str, day: dt.date) -> tuple[np.ndarray, float] | None:
        """(cube_k (30, 2n+1, 2n+1), step_urad) of the day's assessment, or None.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.

        Returns
        -------
        tuple or None
            (cube_k, K, shape (30, 2n+1, 2n+1); step_urad).
        """
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
        """Store the LOS fingerprint of *satellite* on *day* (replacing one computed before).

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        day : datetime.date
            The UTC day.
        body : dict
            The fingerprint's JSON.
        """
        with self.transaction():
            self.db.execute(
                "INSERT OR REPLACE INTO fingerprints VALUES (?, ?, ?, ?)",
                (satellite, day.isoformat(), self._now(), json.dumps(body)),
            )

    def fingerprint(self, satellite: str, before: dt.date) -> tuple[dt.date, dict] | None:
        """(day, body) of the latest fingerprint strictly before *before*, or None.

        Parameters
        ----------
        satellite : str
            The satellite's short name.
        before : datetime.date
            Strictly before this day.

        Returns
        -------
        tuple or None
            (day, body).
        """
        r = self.db.execute(
            "SELECT day, body FROM fingerprints WHERE satellite=? AND day < ? ORDER BY day DESC LIMIT 1",
            (satellite, before.isoformat()),
        ).fetchone()
        return None if r is None else (dt.date.fromisoformat(r["day"]), json.loads(r["body"]))
