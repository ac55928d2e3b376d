"""The store's file: one SQLite connection in WAL mode, created under a temporary name and renamed into
place, refused when it is not a crisgeo store, migrated forward, written in transactions that a full disk
rolls back whole."""

from __future__ import annotations

import datetime as dt
import os
import sqlite3
from collections.abc import Callable
from pathlib import Path
from types import TracebackType
from typing import Literal, Self

from monitor.core.result import ForOffset
from monitor.service.store.alert_state import AlertState
from monitor.service.store.schema import MIGRATIONS, result_columns

UTC = dt.timezone.utc


def utc_now() -> dt.datetime:
    """The time now, UTC (the store's default clock).

    Returns
    -------
    datetime.datetime
        Aware, UTC.
    """
    return dt.datetime.now(UTC)


class StoreError(RuntimeError):
    """The store file cannot be used (corrupt, empty, not a crisgeo store, too new); one line, naming it."""


class Database:
    """The store's SQLite file. One connection per object; use from one thread at a time.

    A store is created only where no file exists (built under a temporary name, then renamed into place);
    an existing file that is empty, corrupt or not a crisgeo store is refused with :class:`StoreError`,
    never re-initialised: it holds the history and the alert state.

    Parameters
    ----------
    path : str or os.PathLike
        The SQLite file.
    create : bool, optional
        Make a new store where there is none; an existing file that is not a store is refused either way.
    clock : callable, optional
        The clock, aware UTC datetimes (:func:`utc_now`).
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

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- schema
    @property
    def schema_version(self) -> int:  # numpydoc ignore=RT01
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
        self.add_result_columns()

    def result_column_types(self) -> dict[str, str]:
        """The columns of the per-FOR results and their SQL types, as the file holds them.

        Returns
        -------
        dict
            Column name to type (``REAL``, ``INTEGER``, ``TEXT``).
        """
        return {r[1]: r[2] for r in self.db.execute("PRAGMA table_info(results)")}

    def add_result_columns(self, record: type = ForOffset) -> list[str]:
        """Give the results a column for every field *record* declares that the file lacks (a new field of a
        newer version; :func:`monitor.service.store.schema.result_columns`).

        Parameters
        ----------
        record : type, optional
            The per-FOR record whose declared fields the columns follow.

        Returns
        -------
        list of str
            The statements run (none when every field has its column).
        """
        added = result_columns(set(self.result_column_types()), record)
        if added:
            with self.transaction():
                for stmt in added:
                    self.db.execute(stmt)
        return added

    def integrity(self) -> str:
        """SQLite's own check of the file (``PRAGMA integrity_check``): ``ok``, or what is wrong.

        Returns
        -------
        str
            ``ok`` for a sound file.
        """
        return "; ".join(str(r[0]) for r in self.db.execute("PRAGMA integrity_check"))

    @property
    def closed(self) -> bool:  # numpydoc ignore=RT01
        """Whether the connection is closed."""
        try:
            self.db.execute("SELECT 1")
        except sqlite3.ProgrammingError:
            return True
        return False

    def _now(self) -> str:
        return self.clock().astimezone(UTC).isoformat(timespec="seconds")

    def transaction(self) -> _Transaction:
        """A context manager: BEGIN IMMEDIATE ... COMMIT, rolled back on an exception; a file system
        without room is a :class:`StoreError` naming the file (the transaction rolled back whole).

        Returns
        -------
        _Transaction
            The context manager.
        """
        return _Transaction(self.db, self.path)

    def alert_state(self) -> AlertState:
        """The alert state, silences and delivery queue of this store.

        Returns
        -------
        AlertState
            Over this store.
        """
        return AlertState(self)


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
