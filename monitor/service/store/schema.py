"""The store's schema: every table as a forward migration, numbered by SQLite's user_version (a file
is brought up to date when opened; never down). The results table has a column for each measured field of a
FOR, derived from its declaration (:func:`result_columns`): a new field is a new column, added when a store
is opened."""

from __future__ import annotations

from monitor.core.result import ForOffset, measures

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
        flags TEXT, PRIMARY KEY (satellite, day, for_index));
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
    # 3: the alert tables (monitor/service/store/alert_state.py), until now created by the alert state
    # itself: IF NOT EXISTS keeps the rows of stores that have them; alert_meta, their own version table, goes
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
    CREATE TABLE difference_bins (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, low_k REAL NOT NULL,
        n INTEGER, mean_k REAL, std_k REAL, PRIMARY KEY (satellite, day, low_k));
    """,
    # 5: the CrIS spatial response seen at each FOR's optimum: its columns, like every measured field's, are
    # the declaration's (result_columns)
    "",
    # 6: an alert's id has no trailing separator when it has no group ("spec:j01", was "spec:j01:"); the
    # silences are keyed on rule and satellite, not on the id, and keep working
    """
    UPDATE alert_state SET fingerprint = rtrim(fingerprint, ':') WHERE fingerprint LIKE '%:';
    """,
    # 7: the jump rule's noise, fitted on every day before a refit date (alerts/steps.py) and kept, so that
    # a daily evaluation reads its replay window only; storing a day before a fit's date drops the fit
    """
    CREATE TABLE noise_fits (
        satellite TEXT NOT NULL, quantity TEXT NOT NULL, before TEXT NOT NULL, body TEXT NOT NULL,
        PRIMARY KEY (satellite, quantity, before));
    """,
    # CrIS minus VIIRS per band, binned (by FOV, scene temperature, node), and one granule's FOVs per band
    """
    CREATE TABLE radiometry_bins (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, band TEXT NOT NULL,
        binned_by TEXT NOT NULL, key TEXT NOT NULL, n INTEGER, mean_k REAL, sigma_k REAL,
        PRIMARY KEY (satellite, day, band, binned_by, key));
    CREATE TABLE difference_maps (
        satellite TEXT NOT NULL, day TEXT NOT NULL, run_id INTEGER NOT NULL, band TEXT NOT NULL,
        body TEXT NOT NULL, PRIMARY KEY (satellite, day, band));
    """,
]


def result_columns(have: set[str], record: type = ForOffset) -> list[str]:
    """The statements adding to the results table a column for each measured field of *record* it lacks
    (*have*: its columns), in declaration order: REAL, or INTEGER for a count.

    Parameters
    ----------
    have : set of str
        The results table's columns.
    record : type, optional
        The per-FOR record.

    Returns
    -------
    list of str
        ``ALTER TABLE`` statements.
    """
    return [
        f"ALTER TABLE results ADD COLUMN {m.name} {'INTEGER' if m.kind is int else 'REAL'}"
        for m in measures(record)
        if m.name not in have
    ]
