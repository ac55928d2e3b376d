"""The daily run on a local source: outcomes recorded, idempotent, corrupt input skipped."""

import collections
import datetime as dt
from pathlib import Path

import pytest

from monitor.archive.local import LocalSource
from monitor.assessment.assess import DayAssessment
from monitor.config.file import load_config
from monitor.core.vocabulary import EventKind
from monitor.service.pipeline import days_to_run, run_day
from monitor.service.store.sqlite import Store
from tests.conftest import tree_with_truncated

DAY = dt.date(2024, 6, 1)
TODAY = dt.datetime.now(dt.timezone.utc).date()  # the runs' date: DAY is long past its no-data horizon


def make_config(tmp_path, data_dir, extra=""):
    p = tmp_path / "c.yaml"
    p.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\n"
        f"source: {{kind: local, path: {data_dir}}}\nassessment: {{workers: 1}}\n"
        f"schedule: {{catch_up_days: 3}}\n{extra}"
    )
    return load_config(p)


def test_run_is_recorded_and_idempotent(cases, tmp_path, monkeypatch):
    """... and single-pass: selection pairs the granules and reads the CrIS files, the VIIRS files' metadata
    is read once when they are fetched, and nothing is read or paired again before the assessment."""
    from monitor.sdr import pairing, readers

    data, truth, reference = cases.get()
    cfg = make_config(tmp_path, data)
    store = Store(cfg.store.sqlite)
    src = LocalSource(data)
    reads = collections.Counter()

    def counting(path):
        reads[Path(path).name[:5]] += 1
        return readers.read_metadata(path)

    monkeypatch.setattr(pairing, "read_metadata", counting)
    monkeypatch.setattr(pairing, "find_files", lambda paths: pytest.fail("the daily run paired files again"))
    first = run_day(cfg, store, src, "j01", DAY, TODAY)
    monkeypatch.undo()
    # two CrIS granules (their GEO metadata read once each, the SDR's came with selection's reading), and one
    # VIIRS granule covering both, fetched and read once
    assert reads == {"GCRSO": 2, "GITCO": 1, "SVI05": 1}, reads
    # the same numbers as assessing the files directly (crisgeo assess)
    assert [f.d_beta_urad for f in first.result.fors] == [f.d_beta_urad for f in reference.fors]
    assert first.status == "ok" and len(first.result.fors) == 30
    assert first.precision.granules == 2 and first.precision.stop == "one batch"
    assert store.latest_precision("j01") == first.precision
    seen = []

    class SameNumbers(DayAssessment):  # the rerun pays for no second assessment: the recording is tested
        def add(self, case, *args, **kw):
            seen.append(len(case.cris))

        def result(self, timings=None):
            return first.result

    second = run_day(cfg, store, src, "j01", DAY, TODAY, assessor=SameNumbers)
    assert second.status == "ok" and seen == [2]
    assert len(store.day_result("j01", DAY)) == 30  # replaced, not added
    assert {g.run_id for g in store.granules("j01", DAY)} == {second.run_id}
    decisions = store.selection("j01", DAY)
    assert len(decisions) == 2 and all(d.decision == "chosen" and d.score_k > 0.5 for d in decisions)
    assert [f.d_beta_urad for f in store.day_result("j01", DAY)] == [
        f.d_beta_urad for f in second.result.fors
    ]


def test_a_day_without_data_is_recorded(cases, tmp_path):
    data, _, _ = cases.get()
    cfg = make_config(tmp_path, data)
    store = Store(cfg.store.sqlite)
    out = run_day(cfg, store, LocalSource(data), "j01", DAY + dt.timedelta(days=3), TODAY)
    assert (
        out.status == "no_data_final" and "no CrIS GEO granule" in out.reason
    )  # long past its retry horizon
    assert store.runs()[0].status == "no_data_final"
    assert DAY + dt.timedelta(days=3) in store.done_days("j01")
    window = cfg.schedule.model_copy(update={"catch_up_days": 4})
    assert days_to_run(store, "j01", window, DAY + dt.timedelta(days=5)) == [
        DAY + dt.timedelta(days=k) for k in (1, 2, 4)
    ]


def test_an_empty_day_is_tried_again_until_its_horizon(cases, tmp_path):
    """An archive outage or late ingest: the day is retried at each run for schedule.no_data_retry_days
    (3) after it is due, and only then recorded as final."""
    data, _, _ = cases.get()
    cfg = make_config(tmp_path, data)
    store = Store(cfg.store.sqlite)
    today = TODAY
    yesterday = today - dt.timedelta(days=1)
    out = run_day(cfg, store, LocalSource(data), "j01", yesterday, today)
    assert out.status == "no_data" and "tried again for 3 day(s)" in out.reason
    week = cfg.schedule.model_copy(update={"catch_up_days": 7})
    for later in range(4):  # due on today; tried again on the next three days
        assert yesterday in days_to_run(store, "j01", week, today + dt.timedelta(days=later)), later
    assert yesterday not in days_to_run(store, "j01", week, today + dt.timedelta(days=4))


def test_corrupt_granule_is_skipped_with_reason_and_the_run_goes_on(cases, tmp_path):
    data, _, _ = cases.get()
    sdr = sorted(data.glob("SCRIF_*.h5"))[0]
    work = tree_with_truncated(data, tmp_path / "data", sdr, keep_bytes=4000)
    cfg = make_config(tmp_path, work)
    store = Store(cfg.store.sqlite)
    out = run_day(cfg, store, LocalSource(work), "j01", DAY, TODAY)
    assert out.status == "ok" and len(out.result.granules) == 1
    rejected = [d for d in store.selection("j01", DAY) if d.decision == "rejected"]
    assert (
        len(rejected) == 1
        and "unusable CrIS granule" in rejected[0].reason
        and sdr.name in rejected[0].reason
    )
    assert len(store.day_result("j01", DAY)) == 30


def test_source_failure_is_a_failed_run_and_an_event(tmp_path):
    """The tree is gone at run time (an unmounted archive): a failed run, not a crash."""
    (tmp_path / "missing").mkdir()
    cfg = make_config(tmp_path, tmp_path / "missing")
    (tmp_path / "missing").rmdir()
    store = Store(cfg.store.sqlite)
    out = run_day(cfg, store, LocalSource(tmp_path / "missing"), "j01", DAY, TODAY)
    assert out.status == "failed" and "no such directory" in out.reason
    (event,) = store.events(EventKind.RUN_FAILED)
    assert event.satellite == "j01" and event.detail == {"day": DAY.isoformat(), "reason": out.reason}


def test_a_poison_day_is_recorded_alerted_and_the_next_day_still_runs(cases, tmp_path, monkeypatch):
    """Any exception inside a satellite-day stops at that day: the run is failed with its reason, the
    failure alert fires, the catch-up goes on with the next day."""
    from monitor.service.daemon import Service
    from monitor.simulate.case import simulate_case

    data, _, _ = cases.get()
    tree = tmp_path / "tree"
    tree.mkdir()
    for f in data.glob("*.h5"):
        (tree / f.name).symlink_to(f)
    simulate_case(
        tree / "next",
        granules=1,
        profile="paper",
        seed=2,
        start=dt.datetime(2024, 6, 2, 12, tzinfo=dt.timezone.utc),
    )
    log = tmp_path / "alerts.log"
    cfg = make_config(tmp_path, tree, f"alerts: {{log: {log}}}\n")

    add = DayAssessment.add

    def poisoned(self, case, *args, **kw):
        if case.cris[0].key.startswith("j01_d20240601"):
            raise RuntimeError("poison granule")
        add(self, case, *args, **kw)

    monkeypatch.setattr(DayAssessment, "add", poisoned)
    outcomes = list(Service(cfg).catch_up("j01", today=DAY + dt.timedelta(days=2)))
    assert [(o.day, o.status) for o in outcomes][-2:] == [(DAY, "failed"), (DAY + dt.timedelta(days=1), "ok")]
    assert outcomes[-2].reason == "unexpected RuntimeError: poison granule"
    store = Store(cfg.store.sqlite)
    assert {r.day: r.status for r in store.runs("j01")}[str(DAY)] == "failed"
    assert any(
        e.kind == EventKind.RUN_FAILED and "poison granule" in e.detail["reason"] for e in store.events()
    )
    text = log.read_text()
    assert "failure" in text and "poison granule" in text


def test_a_local_tree_under_a_relative_path_is_listed(cases, tmp_path):
    """The demo's state lives at configs/../demo-state: a '..' in the root is not a dot segment of a key."""
    data, _, _ = cases.get()
    (tmp_path / "a").mkdir()
    (tmp_path / "tree").symlink_to(data)
    files = LocalSource(tmp_path / "a" / ".." / "tree").list_day("j01", DAY, ("GCRSO", "SCRIF"))
    assert len(files) == 4
