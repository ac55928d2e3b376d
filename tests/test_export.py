"""Results as data: NetCDF (CF, read back with xarray) and CSV exports, and the public API."""

import datetime as dt

import numpy as np
import pytest

xr = pytest.importorskip("xarray")


@pytest.fixture
def store_with_days(tmp_path):
    from monitor import open_store
    from monitor.simulate.history import fill_store

    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01, npp]\nstate_dir: {tmp_path / 'state'}\n"
        f"source: {{kind: local, path: {tmp_path}}}\n"
    )
    store = open_store(tmp_path / "state" / "crisgeo.sqlite")
    fill_store(store, ["j01"], dt.date(2025, 3, 1), 12, step_day=6, seed=3)
    return cfg, store


def test_netcdf_export_reads_back_with_xarray(store_with_days, tmp_path):
    from monitor.cli import main

    cfg, store = store_with_days
    out = tmp_path / "j01.nc"
    assert (
        main(
            [
                "export",
                "--config",
                str(cfg),
                "--satellite",
                "j01",
                "--since",
                "2025-03-03",
                "--until",
                "2025-03-10",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert ds.sizes == {"time": 8, "for": 30} and str(ds.time.values[0])[:10] == "2025-03-03"
    day = dt.date(2025, 3, 5)
    want = {f.for_index: f for f in store.day_result("j01", day)}
    got = ds.sel(time=np.datetime64(day, "ns"))
    assert got.d_beta_urad.sel(**{"for": 21}).item() == pytest.approx(want[21].d_beta_urad)
    assert got.n_samples.sel(**{"for": 7}).item() == want[7].n_samples
    assert ds.d_alpha_urad.attrs["units"] == "urad" and ds.total_km.attrs["units"] == "km"
    meanings = ds.flags.attrs["flag_meanings"].split()
    masks = dict(zip(meanings, ds.flags.attrs["flag_masks"], strict=True))
    bits = ds.flags.values
    series = store.series("j01", dt.date(2025, 3, 3), dt.date(2025, 3, 10))
    assert series.days[0] == dt.date(2025, 3, 3) and bits.shape == series.flags.shape
    for (i, k), names in np.ndenumerate(series.flags):
        assert bits[i, k] == sum(int(masks[f]) for f in names)
    assert any(series.flags.ravel())  # the history has flagged FORs to check
    assert ds.attrs["satellite"] == "j01" and "Wang et al. 2017" in ds.attrs["method"]
    assert ds.attrs["source"].startswith("crisgeo-monitor")


def test_csv_export_and_the_public_api(store_with_days, tmp_path):
    import csv

    import monitor
    from monitor import AssessmentResult, assess_paths, open_store  # noqa: F401 - the public API imports

    cfg, store = store_with_days
    out = tmp_path / "j01.csv"
    from monitor.cli import main

    assert (
        main(["export", "--config", str(cfg), "--satellite", "j01", "--format", "csv", "--out", str(out)])
        == 0
    )
    rows = list(csv.DictReader(out.open()))
    assert len(rows) == 12 * 30 and {"time", "for", "d_alpha_urad", "flags"} <= set(rows[0])
    ds = open_store(store.path).to_xarray("j01", since=dt.date(2025, 3, 12))
    assert ds.sizes["time"] == 1 and callable(monitor.assess_paths)
