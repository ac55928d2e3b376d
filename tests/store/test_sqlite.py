import datetime as dt
import sqlite3

import pytest

from monitor.store.sqlite import MIGRATIONS, Store

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
        s.save_day(run, "j01", DAY, result, [{"granule": "g", "score_k": 1.0, "decision": "chosen"}],
                   {"influx2:http://x": ["m f=1 1"] * 30})
    assert s.db.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 30
    assert s.outbox_size() == 30 and len(s.granules("j01", DAY)) == 2
    assert [r["status"] for r in s.runs("j01")] == ["ok", "ok"]
    assert s.day_result("j01", DAY) == result.fors
    cube, step_urad = s.cost_cube("j01", DAY)
    assert cube.shape == (30, 21, 21) and step_urad == pytest.approx(375.0 / 833000.0 * 1e6)
    assert s.done_days("j01") == {DAY}
    g = s.granules("j01", DAY)[0]
    assert "CMNGEO-PARAM-LUT" in g["cris_aux"] and "VIIRS-SDR-GEO-IMG-PARAM-LUT" in g["viirs_aux"]


def test_failed_transaction_leaves_nothing(cases, tmp_path):
    _, _, result = cases.get()
    s = Store(tmp_path / "d.sqlite")
    run = s.begin_run("j01", DAY)
    with pytest.raises(sqlite3.Error):
        s.save_day(run, "j01", DAY, result, [{"granule": None, "decision": None}], {})  # NOT NULL violated
    assert s.db.execute("SELECT COUNT(*) FROM results").fetchone()[0] == 0
    assert s.runs()[0]["status"] == "running"
    assert s.interrupt_stale_runs() == 1 and s.runs()[0]["status"] == "interrupted"


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
