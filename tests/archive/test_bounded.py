"""The stall window of a transfer (no server: a clock the test moves)."""

from monitor.archive.bounded import StallWatch
from tests.conftest import Clock


def test_a_steady_transfer_never_stalls_and_a_drip_does_after_one_window():
    clock = Clock(100.0)
    steady = StallWatch(min_rate_b_s=1000, window_s=30, clock=clock)
    drip = StallWatch(min_rate_b_s=1000, window_s=30, clock=clock)
    for _ in range(120):  # two minutes: 2000 B/s and 1 B/s
        clock.t += 1
        steady.add(2000)
        drip.add(1)
        assert not steady.stalled()
        assert drip.stalled() == (clock.t - 100 >= 30)


def test_a_fast_start_does_not_pay_for_a_later_stall():
    """A total budget let a fast start carry a dead transfer; the window sees only its last 30 s."""
    clock = Clock(100.0)
    w = StallWatch(min_rate_b_s=1000, window_s=30, clock=clock)
    clock.t += 1
    w.add(10_000_000)
    for _ in range(29):
        clock.t += 1
        w.add(1)
        assert not w.stalled()
    clock.t += 2
    w.add(1)
    assert w.stalled()


def test_the_simulated_source_keeps_only_its_newest_days(tmp_path, monkeypatch):
    """A catch-up of months must not keep every simulated day (~0.2 GB each)."""
    import datetime as dt
    import os
    import time

    import monitor.simulate.case
    from monitor.archive.local import IN_USE_S, SimulatedSource
    from monitor.config.source import SourceConfig

    def fake_case(target, **kw):
        target.mkdir(parents=True)
        (target / "truth.json").write_text("{}")

    monkeypatch.setattr(monitor.simulate.case, "simulate_case", fake_case)
    src = SimulatedSource(tmp_path, SourceConfig(kind="simulated", retention_days=3))
    for k in range(6):
        src.list_day("j01", dt.date(2024, 6, 1) + dt.timedelta(days=k), ("GCRSO",))
        for d in (tmp_path / "j01").iterdir():  # listed long ago, except the one just listed
            if d.name != (dt.date(2024, 6, 1) + dt.timedelta(days=k)).isoformat():
                os.utime(d, (time.time() - IN_USE_S - 60,) * 2)
    assert sorted(d.name for d in (tmp_path / "j01").iterdir()) == ["2024-06-04", "2024-06-05", "2024-06-06"]
    # one source's own days, one after another (the demo's catch-up): done with once the next is listed,
    # unless another run listed them since (it may read them still)
    mine = SimulatedSource(tmp_path / "own", SourceConfig(kind="simulated", retention_days=1))
    mine.list_day("j01", dt.date(2024, 6, 1), ("GCRSO",))
    mine.list_day("j01", dt.date(2024, 6, 2), ("GCRSO",))
    assert sorted(d.name for d in (tmp_path / "own" / "j01").iterdir()) == ["2024-06-02"]
    other = SimulatedSource(tmp_path / "own", SourceConfig(kind="simulated", retention_days=1))
    other.list_day("j01", dt.date(2024, 6, 2), ("GCRSO",))  # another run reads it now
    day2 = tmp_path / "own" / "j01" / "2024-06-02"
    seen = day2.stat().st_mtime_ns + 10**9  # its listing later than this source's own, whatever the clock
    os.utime(day2, ns=(seen, seen))
    mine.list_day("j01", dt.date(2024, 6, 3), ("GCRSO",))
    assert sorted(d.name for d in (tmp_path / "own" / "j01").iterdir()) == ["2024-06-02", "2024-06-03"]


def test_the_download_cache_is_cut_to_its_size_least_recently_used_first(tmp_path):
    import os
    import time

    from monitor.archive.nodd import NoddSource
    from monitor.config.source import SourceConfig

    src = NoddSource(SourceConfig(kind="nodd", cache_max_mb=2.5), tmp_path / "cache")
    folder = tmp_path / "cache" / "GITCO"
    folder.mkdir(parents=True)
    for k in range(5):  # 1 MB each, used k hours ago
        f = folder / f"g{k}.h5"
        f.write_bytes(b"x" * 1_000_000)
        os.utime(f, (time.time() - 3600 * k,) * 2)
    src.start_day()
    assert sorted(p.name for p in folder.iterdir()) == ["g0.h5", "g1.h5"]
