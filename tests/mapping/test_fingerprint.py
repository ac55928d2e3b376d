"""The daily LOS fingerprint: stable on real NOAA-20 data, steps found on simulated mapping-angle changes."""

import datetime as dt

import numpy as np
import pytest

from monitor.archive.local import LocalSource
from monitor.assessment.day import day_fingerprint
from monitor.config.file import load_config
from monitor.history.changes import all_changes, preceding_change
from monitor.mapping import fingerprint as fpr
from monitor.sdr import read_file
from monitor.service.pipeline import record_fingerprint
from monitor.service.store.sqlite import Store
from monitor.simulate.case import SimulationSpec, simulate_case

UTC = dt.timezone.utc
D0 = dt.date(2024, 7, 1)


def test_real_noaa20_fingerprint_is_stable(real_geo_files):
    prints = [fpr.granule_print(read_file(f)[0]) for f in real_geo_files]
    day = fpr.day_print(prints)
    assert day.alpha_urad.shape == (30,) and np.all(np.isfinite(day.beta_urad))
    assert np.max(day.sd_alpha_urad) < 3.0  # in-track: ~1.5 urad scan to scan
    assert np.max(day.sd_beta_urad) < 12.0 and np.min(day.sd_beta_urad) < 3.0  # cross-track: 1.5-9.5 by FOR
    assert fpr.change_within(prints) is None  # no false change over the ten granules
    assert fpr.detect_change(prints, 10.0) is None
    # the 9-FOV pattern: FOV 1 and 9 about 19 mrad from FOV 5 in each direction
    assert 18000 < abs(day.pattern_alpha_urad[14, 0]) < 20000 and abs(day.pattern_alpha_urad[14, 4]) < 1e-6


def test_a_step_in_the_real_prints_is_a_typed_change(real_geo_files):
    """Shift FOR 28-30 of the last six real granules by 60 urad cross-track: against the unshifted day's
    scatter (the previous day, as in the daily run) the change starts at granule 5 and names those FORs;
    a later day made only of shifted granules shows the step against that reference too."""
    import dataclasses

    prints = [fpr.granule_print(read_file(f)[0]) for f in real_geo_files]
    shift = np.where(np.arange(30) >= 27, 60.0, 0.0)
    moved = prints[:4] + [
        dataclasses.replace(p, beta_urad=p.beta_urad + shift, scan_beta_urad=p.scan_beta_urad + shift)
        for p in prints[4:]
    ]
    change = fpr.detect_change(moved, 10.0, reference=fpr.day_print(prints))
    assert change.granule == prints[4].granule_id and change.time == prints[4].start
    assert change.fors == [28, 29, 30] and abs(change.largest_urad - 60) < 10
    assert f"FOR 28, 29, 30, up to {change.largest_urad:.0f} urad" in change.describe() and change.to_dict()[
        "fors"
    ] == [28, 29, 30]
    later = moved[4:]
    between = fpr.detect_change(
        later[:3], 10.0, reference=fpr.day_print(prints[:4]), day=dt.date(2018, 10, 23)
    )
    assert between.time == "2018-10-23T00:00:00+00:00" and set(between.fors) >= {28, 29, 30}


def _day(root, day, d_alpha, d_beta, change_at=None, new=None, n=4, seed=3):
    """Simulate n GEO granules on *day*; from granule *change_at* on, the GEO LOS uses *new* offsets."""
    start = dt.datetime(day.year, day.month, day.day, 12, tzinfo=UTC)
    parts = [(0, n if change_at is None else change_at, d_alpha, d_beta)]
    if change_at is not None:
        parts.append((change_at, n, *new))
    for a, b, da, db in parts:
        if b > a:
            spec = SimulationSpec(
                granules=b - a,
                d_alpha_urad=np.asarray(da, float),
                d_beta_urad=np.asarray(db, float),
                seed=seed,
                start=start + dt.timedelta(seconds=32 * a),
                cris_sdr=False,
            )
            simulate_case(root / f"{day}_{a}", spec=spec, viirs=False)


SCENARIOS = {
    "FOR group by 20 urad": (np.zeros(30), np.r_[np.zeros(20), np.full(10, 20.0)], list(range(21, 31))),
    "all FORs by 300 urad": (np.zeros(30), np.full(30, 300.0), list(range(1, 31))),
    "in-track pitch 50 urad": (np.full(30, 50.0), np.zeros(30), list(range(1, 31))),
}


@pytest.mark.parametrize("name", list(SCENARIOS) + ["no change"])
def test_simulated_change_found_on_the_right_day_granule_and_fors(name, tmp_path):
    zero = np.zeros(30)
    new = SCENARIOS.get(name)
    _day(tmp_path, D0, zero, zero)
    _day(tmp_path, D0 + dt.timedelta(days=1), zero, zero)
    _day(
        tmp_path,
        D0 + dt.timedelta(days=2),
        zero,
        zero,
        change_at=2 if new else None,
        new=new[:2] if new else None,
    )
    _day(tmp_path, D0 + dt.timedelta(days=3), *(new[:2] if new else (zero, zero)))
    cfg_file = tmp_path / "c.yaml"
    cfg_file.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
    )
    cfg = load_config(cfg_file)
    store = Store(cfg.store.sqlite)
    src = LocalSource(tmp_path)
    bodies = []
    for k in range(4):
        day = D0 + dt.timedelta(days=k)
        fingerprint = day_fingerprint(cfg, src, "j01", day, src.list_day("j01", day, ("GCRSO",)))
        assert fingerprint is not None and fingerprint.matches  # the EP identified before anything is stored
        bodies.append(record_fingerprint(cfg, store, "j01", day, fingerprint))
    changed_days = [k for k, b in enumerate(bodies) if "change" in b]
    if new is None:
        assert changed_days == []
        return
    assert changed_days == [2]  # found on the day of the change, not again the day after
    ch = bodies[2]["change"]
    first_changed = sorted(
        read_file(f)[0].meta.granule_id for f in (tmp_path / f"{D0 + dt.timedelta(days=2)}_2").glob("GCRSO*")
    )[0]
    assert ch["granule"] == first_changed
    assert ch["fors"] == new[2]
    # the change is attributed like a calendar event (CrIS), and notified by the alerts
    changes = all_changes(store, "j01")
    assert preceding_change(changes, D0 + dt.timedelta(days=3)).instrument == "cris"
