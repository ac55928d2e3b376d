"""The alert tables of the store: state, silences, the delivery queue; the migration that took them over."""

import datetime as dt
import sqlite3

import pytest

from alerts.rules import Finding
from monitor.core.vocabulary import EventKind
from monitor.history.records import Attachment, Message
from monitor.service.store.alert_state import AlertState, SilenceError
from monitor.service.store.schema import MIGRATIONS
from monitor.service.store.sqlite import Store

T0 = dt.datetime(2026, 11, 22, 6, 0, tzinfo=dt.timezone.utc)


def test_alert_lifecycle_keeps_its_start(tmp_path):
    with Store(tmp_path / "s.sqlite") as store:
        state = AlertState(store)
        f = Finding("spec", "j01", "critical", "FOR 30 beyond spec", ["FOR 30: 1.8 km"])
        state.upsert(f, T0, notified=True)
        state.upsert(f, T0 + dt.timedelta(hours=3), notified=False)
        (row,) = state.firing("j01")
        assert row.started == T0.isoformat() and row.last_notified == T0.isoformat()
        assert state.firing("npp") == []
        state.resolve(f.alert_id, T0 + dt.timedelta(days=1))
        assert state.firing() == [] and state.get(f.alert_id).status == "resolved"


def test_silence_matches_rule_and_satellite_until_it_ends(tmp_path):
    with Store(tmp_path / "s.sqlite") as store:
        state = AlertState(store)
        state.silence("jump", None, T0 + dt.timedelta(hours=2), "EP upload", T0)
        assert state.silenced("jump", "j01", T0 + dt.timedelta(hours=1)).reason == "EP upload"
        assert state.silenced("spec", "j01", T0 + dt.timedelta(hours=1)) is None
        assert state.silenced("jump", "j01", T0 + dt.timedelta(hours=3)) is None
        assert [s.reason for s in state.silences(T0)] == ["EP upload"]


def test_a_silence_needs_a_reason_and_a_future_end_and_lifts_only_what_is_in_force(tmp_path):
    with Store(tmp_path / "s.sqlite") as store:
        state = AlertState(store)
        with pytest.raises(SilenceError, match="--reason"):
            state.silence("jump", None, T0 + dt.timedelta(hours=1), "  ", T0)
        with pytest.raises(SilenceError, match="in the future"):
            state.silence("jump", None, T0, "EP upload", T0)
        assert state.silences(T0) == []
        state.silence("jump", None, T0 + dt.timedelta(hours=1), "EP upload", T0)
        (s,) = state.silences(T0)
        with pytest.raises(SilenceError, match=f"--id {s.id + 1}"):
            state.lift(s.id + 1, T0)
        state.lift(s.id, T0)
        assert state.silences(T0) == []


def test_a_delivery_is_claimed_once_and_retried_after_its_lease(tmp_path):
    with Store(tmp_path / "s.sqlite") as store:
        state = AlertState(store)
        state.enqueue("slack", "j01", Message("s", "t", ""), T0)
        (d,) = state.due(T0)
        assert state.claim(d.id, T0) and not state.claim(d.id, T0)  # a second sender gets nothing
        assert state.due(T0 + dt.timedelta(seconds=599)) == []
        assert [x.id for x in state.due(T0 + dt.timedelta(seconds=601))] == [d.id]  # the sender died
        state.mark(d.id, "sent", T0)
        assert state.deliveries("sent")[0].attempts == 1 and state.due(T0 + dt.timedelta(days=1)) == []


def test_a_queued_message_comes_back_whole_with_its_attachment(tmp_path):
    png = Attachment("trend.png", bytes(range(256)) * 4)
    msg = Message("[crisgeo] j01 WARNING", "FOR 30\nmore", "<pre>FOR 30</pre>", ("*FIRING*",), (png,))
    with Store(tmp_path / "s.sqlite") as store:
        state = AlertState(store)
        state.enqueue("email", "j01", msg, T0)
        (d,) = state.due(T0)
        assert d.body == msg and d.subject == msg.subject


def test_a_store_of_schema_2_with_the_old_alert_tables_keeps_its_alerts(tmp_path):
    path = tmp_path / "old.sqlite"
    db = sqlite3.connect(path)
    for migration in MIGRATIONS[:2]:
        db.executescript(migration)
    db.executescript("""
        CREATE TABLE alert_meta (version INTEGER NOT NULL); INSERT INTO alert_meta VALUES (1);
        CREATE TABLE alert_state (fingerprint TEXT PRIMARY KEY, rule TEXT NOT NULL, satellite TEXT NOT NULL,
            grp TEXT, severity TEXT, status TEXT NOT NULL, started TEXT, last_notified TEXT, resolved TEXT,
            summary TEXT, lines TEXT);
        INSERT INTO alert_state VALUES ('spec:j01:', 'spec', 'j01', '', 'critical', 'firing',
            '2026-11-01', NULL, NULL, 'old', '[]');
        INSERT INTO events (time, kind, satellite, detail)
            VALUES ('2026-11-01', 'run_failed', 'j01', 'a text');
        PRAGMA user_version=2;""")
    db.close()
    with Store(path) as store:
        assert store.schema_version == len(MIGRATIONS)
        (alert,) = AlertState(store).firing("j01")
        assert alert.summary == "old" and alert.alert_id == "spec:j01"  # no trailing separator
        tables = {r[0] for r in store.db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
        assert "alert_meta" not in tables and {"silences", "deliveries"} <= tables
        (event,) = store.events(EventKind.RUN_FAILED)
        assert event.detail == {"text": "a text"}  # a detail from before JSON everywhere


def test_event_detail_is_json(tmp_path):
    with Store(tmp_path / "s.sqlite") as store:
        store.add_event(EventKind.RUN_FAILED, "j01", {"day": "2026-11-21", "reason": "HTTP 503"})
        (e,) = store.events()
        assert e.kind is EventKind.RUN_FAILED and e.detail["reason"] == "HTTP 503"
        assert store.db.execute("SELECT detail FROM events").fetchone()[0].startswith("{")
