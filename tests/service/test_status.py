"""``crisgeo status`` as data and as a Nagios plugin: the reason and perfdata on the first line, the one
"out of spec" rule, silences shown beside the state, the daemon found through its lock."""

import dataclasses
import datetime as dt

import numpy as np
import pytest

from alerts.rules import Finding
from monitor.config.file import load_config
from monitor.core.result import ForOffset
from monitor.service.lock import InstanceLock
from monitor.service.status import NagiosState, Thresholds, status_report
from monitor.service.store.alert_state import AlertState
from monitor.service.store.sqlite import Store
from monitor.simulate.history import day_result

DAY = dt.date(2026, 1, 1)
NOW = dt.datetime(2026, 1, 2, 12, 0, tzinfo=dt.timezone.utc)


def _for(in_track_km, cross_track_km, sigma_km=0.1, flags=()) -> ForOffset:
    return ForOffset(
        1, 0.0, 0.0, 1.0, 1.0, in_track_km, cross_track_km, float(np.hypot(in_track_km, cross_track_km)),
        sigma_km, sigma_km, 100, 0.1, 0.5, flags,
    )  # fmt: skip


@pytest.mark.parametrize(
    "in_track_km,cross_track_km,sigma_km,flags,directions,beyond_doubt",
    [
        (1.2, 1.2, 0.1, (), [], None),  # 1.7 km total, each direction within: within the specification
        (-1.6, 0.2, 0.3, (), ["in-track"], False),  # beyond, but within 2 sigma of it
        (0.1, 2.5, 0.1, (), ["cross-track"], True),
        (3.0, 3.0, 0.1, ("flat",), [], None),  # unreliable: never judged
    ],
)
def test_the_spec_is_per_direction_and_judges_reliable_fors_only(
    in_track_km, cross_track_km, sigma_km, flags, directions, beyond_doubt
):
    breaches = _for(in_track_km, cross_track_km, sigma_km, flags).spec_breaches(1.5)
    assert [b.direction for b in breaches] == directions
    if breaches:
        assert breaches[0].beyond_doubt is beyond_doubt


@pytest.fixture
def state(tmp_path):
    cfg_file = tmp_path / "c.yaml"
    cfg_file.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
    )
    cfg = load_config(cfg_file)
    store = Store(cfg.store.sqlite)
    yield cfg, store
    store.close()


def _save(store, fors):
    result = day_result("j01", DAY, np.random.default_rng(3), 0.0, with_cube=False)
    result = dataclasses.replace(result, fors=fors)
    store.save_day(store.begin_run("j01", DAY), "j01", DAY, result)


def test_the_first_line_carries_the_reason_and_the_perfdata(state):
    cfg, store = state
    fors = [dataclasses.replace(_for(0.2, 0.3), for_index=k + 1) for k in range(30)]
    fors[29] = dataclasses.replace(_for(0.5, -4.52), for_index=30)
    fors[28] = dataclasses.replace(_for(1.2, 1.2), for_index=29)  # 1.7 km total: within, per direction
    _save(store, fors)
    spec = Finding("spec", "j01", "critical", "j01: 1 FOR(s) beyond the 1.5 km specification: FOR 30")
    AlertState(store).upsert(spec, NOW, True)
    status = status_report(cfg, store, now=NOW)
    assert status.state == NagiosState.CRITICAL
    assert status.nagios_line() == (
        "CRITICAL - j01: 1 FOR(s) beyond 1.5 km (worst 4.52 km) "
        "| j01_fors_beyond_spec=1;;;0;30 j01_worst_km=4.520;1.5;;0"
    )
    assert status.to_dict()["satellites"]["j01"]["fors_beyond_spec"] == [30]


def test_a_silence_is_shown_and_leaves_the_state(state):
    cfg, store = state
    AlertState(store).upsert(Finding("jump", "j01", "warning", "a step at FOR 21-30"), NOW, True)
    until = NOW + dt.timedelta(days=3)
    AlertState(store).silence("jump", "j01", until, "known EP change", NOW)
    status = status_report(cfg, store, now=NOW)
    assert status.state == NagiosState.WARNING  # a silence quiets notifications, not the state
    line = status.nagios_line()
    assert line.startswith(
        "WARNING - a step at FOR 21-30 (silenced until 2026-01-05T12:00:00+00:00: known EP"
    )
    assert "silenced until 2026-01-05" in status.text().splitlines()[2]
    assert status.to_dict()["satellites"]["j01"]["alerts"][0]["silence"]["reason"] == "known EP change"


def test_the_next_run_is_shown_only_while_a_daemon_holds_the_state_directory(state):
    import os

    cfg, store = state
    assert status_report(cfg, store, now=NOW).next_run_utc is None
    assert "daemon: not running" in status_report(cfg, store, now=NOW).text()
    with InstanceLock(cfg.state_dir, "run"):  # a one-off run schedules nothing
        assert status_report(cfg, store, now=NOW).daemon_pid is None
    with InstanceLock(cfg.state_dir, "daemon"):
        status = status_report(cfg, store, now=NOW)
        assert status.daemon_pid == os.getpid()
        assert status.next_run_utc == dt.datetime(2026, 1, 3, 3, 30, tzinfo=dt.timezone.utc)
        assert f"daemon: pid {os.getpid()}, next scheduled run 2026-01-03 03:30 UTC" in status.text()
    assert status_report(cfg, store, now=NOW).daemon_pid is None  # released


def test_the_table_has_a_units_row_and_prints_gaps(state):
    cfg, store = state
    fors = [dataclasses.replace(_for(0.2, 0.3), for_index=k + 1) for k in range(30)]
    fors[0] = dataclasses.replace(fors[0], d_alpha_urad=float("nan"))
    _save(store, fors)
    text = status_report(cfg, store, now=NOW).text().splitlines()
    header = next(i for i, line in enumerate(text) if line.split()[:1] == ["FOR"])
    assert text[header].split()[:-1] == ["FOR", "d_alpha", "d_beta", "in-trk", "x-trk", "total"]
    assert text[header + 1].split() == ["urad", "urad", "km", "km", "km"]
    assert text[header + 2].split()[1] == "nan"


def test_thresholds_and_staleness_raise_the_state_as_the_plugin_guidelines_say(state):
    """-w/-c on the worst error and on the FORs beyond the specification (monitoring-plugins ranges), and no
    successful assessment for stale_days: each raises the state; none lowers an alert's."""
    from nagiosplugin import Range

    cfg, store = state
    fors = [dataclasses.replace(_for(0.2, 0.3), for_index=k + 1) for k in range(30)]
    fors[5] = dataclasses.replace(_for(1.2, -0.4), for_index=6)
    _save(store, fors)
    fresh = dt.datetime.now(dt.timezone.utc)  # the run was recorded just now
    assert status_report(cfg, store, now=fresh).state == NagiosState.OK  # 1.2 km: within the default, 1.5

    def state(**ranges):
        return status_report(cfg, store, now=fresh, thresholds=Thresholds(**ranges))

    assert state(warning_km=Range("1.0")).state == NagiosState.WARNING
    critical = state(warning_km=Range("1.0"), critical_km=Range("1.1"))
    assert critical.state == NagiosState.CRITICAL
    assert critical.nagios_line() == (
        "CRITICAL - j01: worst 1.20 km, 0 FOR(s) beyond 1.5 km (thresholds: CRITICAL) "
        "| j01_fors_beyond_spec=0;;;0;30 j01_worst_km=1.200;1.0;1.1;0"
    )
    assert state(critical_fors=Range("@0:0")).state == NagiosState.CRITICAL  # no FOR beyond: inside alerts
    assert state(warning_km=Range("@1.0:")).state == NagiosState.WARNING
    assert state(warning_km=Range("2")).state == NagiosState.OK
    # three days after the only run: stale beyond 2 days, not beyond 5
    late = fresh + dt.timedelta(days=3)
    stale = status_report(cfg, store, now=late)
    assert stale.state == NagiosState.WARNING and "no successful assessment since" in stale.nagios_line()
    assert status_report(cfg, store, now=late, thresholds=Thresholds(stale_days=5)).state == NagiosState.OK
