"""The daily run writes the day's mapping on its own offsets when the configuration asks for it, and stores
the offsets read in M15 where it lists M15."""

from __future__ import annotations

import datetime as dt
import math

import pytest

from monitor.service.store.sqlite import Store
from tests.invoke import run_crisgeo

xr = pytest.importorskip("xarray")
DAY = "2026-03-03"


def test_the_daily_run_maps_its_day_onto_the_configured_bands(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\n"
        "source: {kind: simulated, granules: 1}\nscenes: {keep: 1}\n"
        "mapping_dir: maps\nmapping_bands: [I5, M15]\n"
    )
    done = run_crisgeo("run", "--config", cfg, "--date", DAY)
    assert done.returncode in (0, 2), done.stderr  # 2: the simulated day's errors beyond the spec page
    path = tmp_path / "maps" / "j01" / f"j01_{DAY}.nc"
    assert path.exists(), done.stderr[-2000:]
    ds = xr.open_dataset(path, engine="h5netcdf")
    assert list(ds.band.values) == ["I5", "M15"]
    assert ds.attrs["geolocation"] == "assessed"
    assert ds.sizes["scan"] == 4
    d = (ds.cris_bt_k - ds.viirs_bt_k).where(ds.viirs_bt_std_k < 0.5)
    assert abs(float(d.median())) < 0.1
    assert "wrote the day's mapping" in done.stderr


def test_a_bad_band_in_the_configuration_is_refused_in_one_line(tmp_path):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: simulated}}\n"
        "mapping_dir: maps\nmapping_bands: [M14]\n"
    )
    done = run_crisgeo("check-config", "--config", cfg)
    assert done.returncode == 2 and "mapping_bands" in done.stderr and "M14" in done.stderr


def test_the_daily_run_stores_the_offsets_read_in_m15(tmp_path):
    """With M15 in assessment.bands the day is assessed in M15 too, and the store keeps its offsets."""
    cfg = tmp_path / "c.yaml"
    state = tmp_path / "state"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {state}\n"
        "source: {kind: simulated, granules: 1}\nscenes: {keep: 1}\nassessment: {bands: [I5, M15]}\n"
    )
    done = run_crisgeo("run", "--config", cfg, "--date", DAY)
    assert done.returncode in (0, 2), done.stderr
    (db,) = state.rglob("*.sqlite")
    fors = Store(db).day_result("j01", dt.date.fromisoformat(DAY))
    assert len(fors) == 30
    read = [f for f in fors if math.isfinite(f.d_alpha_urad) and math.isfinite(f.d_alpha_urad_M15)]
    assert len(read) >= 20
    assert all(abs(f.d_alpha_urad_M15 - f.d_alpha_urad - f.m15_minus_i5_alpha_urad) < 1e-6 for f in read)
