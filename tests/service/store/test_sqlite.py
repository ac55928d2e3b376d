import datetime as dt
import sqlite3
from dataclasses import astuple

import numpy as np
import pytest

from monitor.core.result import SceneDecision
from monitor.core.vocabulary import Decision
from monitor.service.store.outbox import QueuedLines
from monitor.service.store.schema import MIGRATIONS
from monitor.service.store.sqlite import Store
from tests.invoke import run_crisgeo

DAY = dt.date(2024, 6, 1)


def test_schema_version_and_reopen(tmp_path):
    s = Store(tmp_path / "a.sqlite")
    assert s.schema_version == len(MIGRATIONS)
    assert s.db.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
    s.close()
    assert Store(tmp_path / "a.sqlite").schema_version == len(MIGRATIONS)


def test_newer_schema_is_refused(tmp_path):
    db = sqlite3.connect(tmp_path / "b.sqlite")
    db.execute("PRAGMA user_version=99")
    db.close()
    with pytest.raises(RuntimeError, match="newer than this program"):
        Store(tmp_path / "b.sqlite")


def test_save_day_replaces_and_queues(cases, tmp_path):
    _, _, result = cases.get()
    s = Store(tmp_path / "c.sqlite")
    for _ in range(2):
        run = s.begin_run("j01", DAY)
        s.save_day(
            run,
            "j01",
            DAY,
            result,
            [SceneDecision("g", Decision.CHOSEN, "rank 1", 1.0)],
            [QueuedLines("influx2:http://x", ["m f=1 1"] * 30)],
        )
    assert s.db.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 30
    assert s.outbox_size() == 30 and len(s.granules("j01", DAY)) == 2
    assert [r.status for r in s.runs("j01")] == ["ok", "ok"]
    assert [f.to_dict() for f in s.day_result("j01", DAY)] == [
        f.to_dict() for f in result.fors
    ]  # NaN as None
    cube, step_urad = s.cost_cube("j01", DAY)
    assert cube.shape == (30, 21, 21) and step_urad == pytest.approx(375.0 / 833000.0 * 1e6)
    assert s.done_days("j01") == {DAY}
    g = s.granules("j01", DAY)[0]
    assert any(f.startswith("CMNGEO-PARAM-LUT") for f in g.cris_aux)  # a tuple of the file names
    assert any(f.startswith("VIIRS-SDR-GEO-IMG-PARAM-LUT") for f in g.viirs_aux)


def test_the_intercalibration_and_its_bins_are_stored_with_the_day(cases, tmp_path):
    _, _, result = cases.get()
    assert result.difference_bins and any(np.isfinite(f.bias_k) for f in result.fors)
    s = Store(tmp_path / "i.sqlite")
    s.save_day(s.begin_run("j01", DAY), "j01", DAY, result)
    stored = s.day_result("j01", DAY)
    for name in ("bias_k", "sigma_bias_k", "gain_pct", "sigma_gain_pct", "curvature_k", "sigma_curvature_k"):
        np.testing.assert_array_equal(
            [getattr(f, name) for f in stored], [getattr(f, name) for f in result.fors]
        )
        np.testing.assert_array_equal(
            s.series("j01").values[name][0], [getattr(f, name) for f in result.fors]
        )
    # a bin of one sample has no spread: NaN, stored as NULL and read back as NaN
    np.testing.assert_equal(
        [astuple(b) for b in s.difference_bins("j01", DAY)], [astuple(b) for b in result.difference_bins]
    )
    assert s.difference_bins("j01", DAY + dt.timedelta(days=1)) == []


# the measured columns of schema 1's results table (the columns now derive from ForOffset's declaration)
SCHEMA_1_RESULTS = (
    "d_alpha_urad REAL", "d_beta_urad REAL", "sigma_alpha_urad REAL", "sigma_beta_urad REAL",
    "in_track_km REAL", "cross_track_km REAL", "total_km REAL", "sigma_in_track_km REAL",
    "sigma_cross_track_km REAL", "n_samples INTEGER", "cost_min_k REAL", "cost_zero_k REAL",
)  # fmt: skip


def test_a_store_of_schema_3_gains_the_intercalibration_and_keeps_its_rows(tmp_path):
    """The days stored before the intercalibration read back with NaN for it, not a number."""
    path = tmp_path / "old.sqlite"
    db = sqlite3.connect(path)
    for version, script in enumerate(MIGRATIONS[:3], start=1):
        db.executescript(script)
        db.execute(f"PRAGMA user_version={version}")
    for column in SCHEMA_1_RESULTS:  # the measured columns the results table had then
        db.execute(f"ALTER TABLE results ADD COLUMN {column}")
    db.execute(
        "INSERT INTO results (satellite, day, for_index, run_id, d_alpha_urad, n_samples, flags) "
        "VALUES ('j01', ?, 1, 1, 12.5, 40, '[]')",
        (DAY.isoformat(),),
    )
    db.commit()
    db.close()
    s = Store(path)
    assert s.schema_version == len(MIGRATIONS)
    (f,) = s.day_result("j01", DAY)
    assert f.d_alpha_urad == 12.5 and np.isnan(f.bias_k) and np.isnan(f.gain_pct)
    assert s.difference_bins("j01", DAY) == []


def test_failed_transaction_leaves_nothing(cases, tmp_path):
    _, _, result = cases.get()
    s = Store(tmp_path / "d.sqlite")
    run = s.begin_run("j01", DAY)
    with pytest.raises(sqlite3.Error):
        s.save_day(run, "j01", DAY, result, [SceneDecision(None, None, None)])  # NOT NULL violated
    assert s.db.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 0
    assert s.runs()[0].status == "running"
    assert s.interrupt_stale_runs() == 1 and s.runs()[0].status == "interrupted"


def test_outbox_delivery_bookkeeping(tmp_path):
    s = Store(tmp_path / "e.sqlite")
    run = s.begin_run("j01", DAY)
    s.finish_run(run, "no_data", "nothing listed")
    with s.transaction():
        for i in range(3):
            s.db.execute("INSERT INTO outbox (target, line, created) VALUES ('t', ?, 'now')", (f"l{i}",))
    rows = s.outbox("t")
    s.outbox_failed([r["id"] for r in rows], "down")
    assert s.db.execute("SELECT MAX(attempts) FROM outbox").fetchone()[0] == 1
    s.outbox_delivered([rows[0]["id"]])
    assert s.outbox_size("t") == 2
    assert s.done_days("j01") == {DAY}


@pytest.mark.parametrize(
    "content,reason",
    [
        (b"", "empty file, not a crisgeo store"),
        (b"SQLite format 3\x00" + bytes(range(256)) * 20, "not a usable"),
        (b"not a database at all" * 100, "not a usable"),
    ],
)
def test_an_unusable_store_is_refused_and_left_as_it_is(tmp_path, content, reason):
    from monitor.service.store.database import StoreError

    path = tmp_path / "store.sqlite"
    path.write_bytes(content)
    with pytest.raises(StoreError, match=f"{path}: {reason}"):
        Store(path)
    assert path.read_bytes() == content  # never re-initialised: the history may still be recovered


def test_a_foreign_sqlite_file_is_refused(tmp_path):
    from monitor.service.store.database import StoreError

    db = sqlite3.connect(tmp_path / "other.sqlite")
    db.execute("CREATE TABLE t (x)")
    db.close()
    with pytest.raises(StoreError, match="not a crisgeo store"):
        Store(tmp_path / "other.sqlite")


def test_cli_reports_a_corrupt_store_in_one_line(tmp_path):

    (tmp_path / "state").mkdir()
    (tmp_path / "state" / "crisgeo.sqlite").write_bytes(b"garbage" * 500)
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
    )
    r = run_crisgeo("alerts", "list", "--config", cfg)
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "crisgeo.sqlite: not a usable crisgeo store" in r.stderr
    r = run_crisgeo("status", "--config", cfg)
    assert r.returncode == 3 and r.stdout.startswith("UNKNOWN - ")  # status speaks Nagios, on stdout


def test_what_the_rules_read_of_a_long_history_is_bounded_by_what_they_ask(tmp_path):
    """What the alert rules read of a long history: the runs from the latest success on (all of them when
    none succeeded), the fields and the period of the series asked for, the granules from a day on."""
    from monitor.core.vocabulary import RunStatus
    from monitor.simulate.history import fill_store

    s = Store(tmp_path / "r.sqlite")
    failed = s.begin_run("npp", DAY)
    s.finish_run(failed, RunStatus.FAILED, "no data yet")
    assert [r.id for r in s.runs_since_success("npp")] == [failed]  # none succeeded: every run
    days = fill_store(s, ["j01"], DAY, 40)
    late = s.begin_run("j01", days[-1] + dt.timedelta(days=1))
    s.finish_run(late, RunStatus.FAILED, "disk full")
    runs = s.runs("j01")
    assert s.runs_since_success("j01") == runs[-2:]  # the last ok one, then the failure
    part = s.series("j01", since=days[30], fields=("d_beta_urad", "sigma_beta_urad"))
    whole = s.series("j01")
    assert part.days == days[30:] and set(part.values) == {"d_beta_urad", "sigma_beta_urad"}
    np.testing.assert_array_equal(part.values["d_beta_urad"], whole.values["d_beta_urad"][30:])
    assert (part.flags == whole.flags[30:]).all() and (part.reliable() == whole.reliable()[30:]).all()
    with pytest.raises(ValueError, match="no measured field d_gamma_urad"):
        s.series("j01", fields=("d_gamma_urad",))


def test_a_kept_noise_fit_is_dropped_when_a_day_it_covers_is_stored_again(tmp_path):
    from monitor.simulate.history import day_result, fill_store

    s = Store(tmp_path / "n.sqlite")
    days = fill_store(s, ["j01", "npp"], DAY, 10)
    for before in (days[3], days[8]):
        s.keep_noise_fit("j01", "jump", before, {"days": 3})
    s.keep_noise_fit("npp", "jump", days[8], {"days": 8})
    assert s.noise_fit("j01", "jump", days[8]) == {"days": 3} and s.noise_fit("j01", "jump", days[5]) is None
    s.save_day(
        s.begin_run("j01", days[5]), "j01", days[5], day_result("j01", days[5], np.random.default_rng(2))
    )
    assert s.noise_fit("j01", "jump", days[3]) == {"days": 3}  # fitted before the day: kept
    assert s.noise_fit("j01", "jump", days[8]) is None  # it covered the day: fitted anew when next needed
    assert s.noise_fit("npp", "jump", days[8]) == {"days": 8}  # another satellite's
