"""The store's schema: every table as a forward migration, numbered by SQLite's user_version (a file
is brought up to date when opened; never down)."""

from __future__ import annotations

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
    # NOT EXISTS keeps the rows of stores that have them; alert_meta, their own version table, goes
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
    # monitor/estimation/estimate.py); days stored before have none (NULL)
    """
    ALTER TABLE results ADD COLUMN response_width_50_urad REAL;
    ALTER TABLE results ADD COLUMN sigma_response_width_50_urad REAL;
    ALTER TABLE results ADD COLUMN response_width_10_urad REAL;
    ALTER TABLE results ADD COLUMN sigma_response_width_10_urad REAL;
    """,
]
