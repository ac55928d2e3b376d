"""``crisgeo reprocess`` on a real Dask LocalCluster (2 worker processes) over simulated days."""

import datetime as dt
import math
import threading

import pytest

from monitor.archive.local import LocalSource
from monitor.config.file import load_config
from monitor.service import allocator
from monitor.service.pipeline import run_day
from monitor.service.reprocess import _client, day_task, period_days, reprocess
from monitor.service.store.sqlite import Store

pytestmark = pytest.mark.servers

DAYS = (dt.date(2024, 3, 1), dt.date(2024, 3, 3))
FIELDS = (
    "for_index",
    "d_alpha_urad",
    "d_beta_urad",
    "sigma_alpha_urad",
    "in_track_km",
    "cross_track_km",
    "n_samples",
)


def _config(tmp_path, name, source):
    p = tmp_path / f"{name}.yaml"
    p.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / name}\nsource: {source}\n"
        "assessment: {workers: 1, half_steps: 6}\nscenes: {candidates: 4, keep: 2}\n"
    )
    return load_config(p)


def _plain(v):
    """NaN as None, so that rows compare equal when they hold the same values."""
    return None if isinstance(v, float) and math.isnan(v) else v


def _results(cfg, day=None):
    """(rows (day, FOR, offsets, km, samples) of the stored results, the runs (day, status)), as the store
    gives them back."""
    with Store(cfg.store.sqlite) as s:
        days = (
            [dt.date.fromisoformat(day)] if day else sorted({dt.date.fromisoformat(r.day) for r in s.runs()})
        )
        rows = [
            (d.isoformat(), *(_plain(getattr(f, k)) for k in FIELDS))
            for d in days
            for f in s.day_result("j01", d)
        ]
        return rows, [(r.day, r.status) for r in s.runs()]


@pytest.fixture(scope="module")
def reprocessed(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("reprocess")
    cfg = _config(tmp, "state", "{kind: simulated, granules: 1}")
    summary = reprocess(cfg, *DAYS, ["j01"], workers=2)
    return tmp, cfg, summary


def test_each_day_once_with_the_daily_runs_numbers(reprocessed):
    tmp, cfg, summary = reprocessed
    assert summary.statuses == {"ok": 3} and summary.unfinished == 0 and summary.skipped_done == 0
    rows, runs = _results(cfg)
    days = [d.isoformat() for d in period_days(*DAYS)]
    assert sorted(runs) == [(d, "ok") for d in days]
    assert [r[0] for r in rows] == [d for d in days for _ in range(30)]  # 30 FORs per day, once
    # the daily run of the middle day, on the same granules, stores the same numbers
    middle = days[1]
    daily = _config(tmp, "daily", f"{{kind: local, path: {cfg.state_dir / 'simulated' / 'j01' / middle}}}")
    with Store(daily.store.sqlite) as store:
        assert (
            run_day(
                daily, store, LocalSource(daily.source.path), "j01", DAYS[0].replace(day=2), dt.date.today()
            ).status
            == "ok"
        )
    assert _results(daily, middle)[0] == _results(cfg, middle)[0]


def test_a_second_call_does_nothing(reprocessed):
    _, cfg, _ = reprocessed
    before = _results(cfg)
    again = reprocess(cfg, *DAYS, ["j01"], workers=2)
    assert again.skipped_done == 3 and again.finished == 0 and again.unfinished == 0
    assert _results(cfg) == before


def test_an_interrupted_call_records_what_finished_and_resumes(reprocessed, tmp_path):
    tmp, _, _ = reprocessed
    # the granules are simulated already: read them from the first state directory
    cfg = _config(tmp_path, "resume", "{kind: simulated, granules: 1}")
    cfg.state_dir.mkdir(parents=True)
    (cfg.state_dir / "simulated").symlink_to(tmp / "state" / "simulated")
    stop = threading.Event()
    first = reprocess(cfg, *DAYS, ["j01"], workers=2, progress=lambda out: stop.set(), stop=stop)
    assert first.finished >= 1 and first.unfinished >= 1 and first.finished + first.unfinished == 3
    _, runs = _results(cfg)
    assert len(runs) == first.finished and all(s == "ok" for _, s in runs)  # nothing half-recorded
    rest = reprocess(cfg, *DAYS, ["j01"], workers=2)
    assert rest.skipped_done == first.finished and rest.finished == first.unfinished
    rows, runs = _results(cfg)
    assert sorted(runs) == [(d.isoformat(), "ok") for d in period_days(*DAYS)] and len(rows) == 90


def test_days_found_empty_for_good_are_done(tmp_path):
    (tmp_path / "none").mkdir()
    cfg = _config(tmp_path, "empty", f"{{kind: local, path: {tmp_path / 'none'}}}")
    first = reprocess(cfg, *DAYS, ["j01"], workers=1)
    assert first.statuses == {"no_data_final": 3}  # long past: no retry
    again = reprocess(cfg, *DAYS, ["j01"], workers=1)
    assert again.skipped_done == 3 and again.finished == 0


@pytest.mark.skipif(allocator._glibc() is None, reason="the settings are glibc's")
def test_a_worker_reuses_freed_memory_once_it_runs_a_day(tmp_path):
    """Dask starts workers that hand every freed array back to the system; a satellite-day sets the
    allocator as every crisgeo command does, so that the next arrays reuse the memory."""

    def refault_count():  # a local function: sent to the worker by value
        import resource

        import numpy as np

        a = np.ones(50_000_000)  # 400 MB written, then freed
        del a
        f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        np.ones(50_000_000)
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0

    (tmp_path / "none").mkdir()
    cfg = _config(tmp_path, "empty", f"{{kind: local, path: {tmp_path / 'none'}}}")
    client, cluster = _client(None, 1)
    try:
        (before,) = client.run(refault_count).values()
        client.submit(day_task, cfg, "j01", DAYS[0], pure=False).result()
        (after,) = client.run(refault_count).values()
    finally:
        client.close()
        cluster.close()
    assert before > 150  # 400 MB of fresh pages (2 MB huge pages at the least)
    assert after < before / 10
