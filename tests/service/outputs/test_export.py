"""Results as data: NetCDF (CF, read back with xarray) and CSV exports, and the public API."""

import datetime as dt
import json
import re

import numpy as np
import pytest

xr = pytest.importorskip("xarray")


@pytest.fixture
def store_with_days(tmp_path):
    from monitor.service.store.sqlite import Store
    from monitor.simulate.history import fill_store

    cfg = tmp_path / "c.yaml"
    cfg.write_text(
        f"satellites: [j01, npp]\nstate_dir: {tmp_path / 'state'}\n"
        f"source: {{kind: local, path: {tmp_path}}}\n"
    )
    store = Store(tmp_path / "state" / "crisgeo.sqlite")
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
    assert (
        ds.sizes == {"time": 8, "scan_position": 30, "nv": 2, "band": 4}
        and str(ds.time.values[0])[:10] == "2025-03-03"
    )
    day = dt.date(2025, 3, 5)
    want = {f.for_index: f for f in store.day_result("j01", day)}
    got = ds.sel(time=np.datetime64(day, "ns"))
    assert got.d_beta_urad.sel(scan_position=21).item() == pytest.approx(want[21].d_beta_urad)
    assert got.n_samples.sel(scan_position=7).item() == want[7].n_samples
    assert ds.sel(scan_position=1).total_km.sizes == {"time": 8}
    assert ds.d_alpha_urad.attrs["units"] == "urad" and ds.total_km.attrs["units"] == "km"
    # the CrIS-VIIRS intercalibration at the optimum
    assert got.bias_k.sel(scan_position=3).item() == pytest.approx(want[3].bias_k)
    assert got.gain_pct.sel(scan_position=3).item() == pytest.approx(want[3].gain_pct)
    assert ds.bias_k.attrs["units"] == "K" and ds.gain_pct.attrs["units"] == "percent"
    assert np.isfinite(ds.sigma_bias_k).all() and np.isfinite(ds.sigma_gain_pct).all()
    # CrIS minus VIIRS per band: one variable on the band dimension, each band's stored column in it
    assert list(ds.band_name.values) == ["M13", "M15", "I5", "M16"]  # by wavelength, the coordinate
    assert ds.band.attrs["units"] == "um" and (np.diff(ds.band.values) > 0).all()
    got = got.swap_dims(band="band_name")
    assert ds.cris_minus_viirs_k.dims == ("time", "scan_position", "band")
    meaning = ds.cris_minus_viirs_k.attrs["long_name"]
    assert ds.cris_minus_viirs_k.attrs["units"] == "K" and "M15" not in meaning
    for band in ("I5", "M15"):
        stored = getattr(want[4], f"cris_minus_viirs_k_{band}")
        assert got.cris_minus_viirs_k.sel(scan_position=4, band_name=band).item() == pytest.approx(stored)
    assert "cris_minus_viirs_k_M15" not in ds and np.isfinite(ds.sigma_cris_minus_viirs_k).all()
    meanings = ds.flags.attrs["flag_meanings"].split()
    masks = dict(zip(meanings, ds.flags.attrs["flag_masks"], strict=True))
    bits = ds.flags.transpose("time", "scan_position").values
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
    assert len(rows) == 12 * 30 and {"time", "scan_position", "d_alpha_urad", "flags"} <= set(rows[0])
    ds = open_store(store.path).to_xarray("j01", since=dt.date(2025, 3, 12))
    assert ds.sizes["time"] == 1 and callable(monitor.assess_paths)


def test_the_netcdf_is_cf_1_8_and_acdd(store_with_days, tmp_path):
    """The IOOS compliance checker's CF-1.8 check passes with no high- or medium-priority failure; the ACDD
    attributes, the time axis and its bounds are there."""
    cc = pytest.importorskip("compliance_checker.runner")
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    from monitor.service.outputs.export import export

    _, store = store_with_days
    out = export(store, "j01", tmp_path / "j01.nc", "netcdf")
    CheckSuite.load_all_available_checkers()
    report = tmp_path / "cf.json"
    ok, errors = ComplianceChecker.run_checker(
        str(out), ["cf:1.8"], verbose=0, criteria="normal", output_filename=str(report), output_format="json"
    )
    assert cc is not None and ok and not errors, report.read_text()[:3000]
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert ds.time.attrs["standard_name"] == "time" and ds.time.attrs["axis"] == "T"
    assert ds.time.attrs["bounds"] == "time_bnds"
    assert (ds.time_bnds.values[:, 1] - ds.time_bnds.values[:, 0] == np.timedelta64(1, "D")).all()
    for key in ("title", "summary", "references", "history", "date_created", "source", "Conventions"):
        assert ds.attrs[key], key
    assert "doi:10.1002/2016JD025812" in ds.attrs["references"] and "ACDD-1.3" in ds.attrs["Conventions"]
    assert ds.attrs["time_coverage_start"] == "2025-03-01T00:00:00Z"


def _publisher_config(tmp_path):
    cfg = tmp_path / "p.yaml"
    cfg.write_text(
        f"satellites: [j01]\nstate_dir: {tmp_path / 'state'}\nsource: {{kind: local, path: {tmp_path}}}\n"
        "export:\n  institution: NOAA STAR\n  creator_name: CrIS SDR team\n"
        "  creator_email: cris@example.org\n  creator_url: https://example.org/cris\n  license: CC0-1.0\n"
        "  naming_authority: gov.noaa.star\n  project: JPSS\n"
    )
    return cfg


def test_acdd_1_3_leaves_only_what_does_not_apply(store_with_days, tmp_path):
    """The compliance checker's ACDD-1.3 check, run for real: every highly recommended and recommended
    attribute is there but the CF standard names (none exists for these quantities) and the geospatial
    extent (the file is per scan position, not per place); the time coverage matches the time axis."""
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    from monitor.cli import main

    _, store = store_with_days
    out = tmp_path / "j01.nc"
    assert main(["export", "--config", str(_publisher_config(tmp_path)), "--out", str(out)]) == 0
    CheckSuite.load_all_available_checkers()
    report = tmp_path / "acdd.json"
    ComplianceChecker.run_checker(
        str(out),
        ["acdd:1.3"],
        verbose=0,
        criteria="lenient",
        output_filename=str(report),
        output_format="json",
    )
    doc = json.loads(report.read_text())["acdd:1.3"]
    problems = [
        m
        for group in ("high_priorities", "medium_priorities")
        for check in doc[group]
        for m in check["msgs"]
        if not re.search(r"standard_name|geospatial", m)
    ]
    assert problems == [], problems
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert all(ds[v].attrs["coverage_content_type"] for v in ds.data_vars if v != "time_bnds")
    assert ds.attrs["institution"] == "NOAA STAR" and ds.attrs["license"] == "CC0-1.0"
    assert ds.attrs["id"] == "crisgeo_j01_20250301_20250312" and ds.attrs["time_coverage_duration"] == "P12D"


def test_time_is_first_and_unlimited_and_the_sign_is_stated_once(store_with_days, tmp_path):
    import h5netcdf

    from monitor.service.outputs.export import SIGN_CONVENTION, export

    _, store = store_with_days
    out = export(store, "j01", tmp_path / "j01.nc")
    with h5netcdf.File(out, "r") as f:
        assert f.dimensions["time"].isunlimited() and not f.dimensions["scan_position"].isunlimited()
        assert f.variables["d_alpha_urad"].dimensions == ("time", "scan_position")
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert ds.attrs["sign_convention"] == SIGN_CONVENTION
    named = [v for v in ds.data_vars if "sign_convention" in ds[v].attrs.get("long_name", "")]
    assert set(named) == {"d_alpha_urad", "d_beta_urad", "in_track_km", "cross_track_km"}


@pytest.mark.parametrize(
    "name,fmt,message",
    [
        ("y.csv", "netcdf", "--out {out}: a .csv file cannot hold --format netcdf"),
        ("y.dat", None, "--out {out}: name it .nc or .csv, or give --format"),
    ],
)
def test_the_format_follows_the_name_of_the_file(store_with_days, tmp_path, capsys, name, fmt, message):
    from monitor.cli import main

    cfg, _ = store_with_days
    out = tmp_path / name
    argv = ["export", "--config", str(cfg), "--satellite", "j01", "--out", str(out)]
    assert main(argv + (["--format", fmt] if fmt else [])) == 2
    assert message.format(out=out) in capsys.readouterr().err and not out.exists()
    csv_out = tmp_path / "z.csv"
    assert main(["export", "--config", str(cfg), "--satellite", "j01", "--out", str(csv_out)]) == 0
    assert csv_out.read_text().startswith("time,scan_position,")  # CSV, not NetCDF


def test_the_notebook_store_opens_an_existing_store_and_closes_it(tmp_path):
    """``monitor.open_store``: the results as xarray over the SQLite store, which it closes after a block."""
    from monitor import open_store
    from monitor.service.store.sqlite import Store
    from monitor.simulate.history import fill_store

    with Store(tmp_path / "s.sqlite") as store:
        fill_store(store, ["j01"], dt.date(2026, 11, 22), 2, step_day=None, seed=3)
    with open_store(tmp_path / "s.sqlite") as nb:
        ds = nb.to_xarray("j01")
        assert ds.sizes["time"] == 2 and ds.sizes["scan_position"] == 30
    assert nb.store.closed


def test_what_each_change_did_exports_as_cf_netcdf_and_csv(store_with_days, tmp_path):
    """``crisgeo export --changes``: the EP upload of the calendar on the step's day, per FOR: the 800 urad
    cross-track move of FORs 21-30, significant there only; CF-1.8 clean; a CSV row per change and FOR."""
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    from monitor.cli import main

    cfg, _ = store_with_days
    (tmp_path / "events.yaml").write_text(
        "events:\n  - {satellite: j01, time: '2025-03-07T12:00:00Z', instrument: cris, kind: ep_upload, "
        "description: EP V116}\n"
    )
    cfg.write_text(cfg.read_text() + f"alerts: {{events_file: {tmp_path / 'events.yaml'}}}\n")
    nc, csv = tmp_path / "changes.nc", tmp_path / "changes.csv"
    for out in (nc, csv):
        assert (
            main(["export", "--changes", "--config", str(cfg), "--satellite", "j01", "--out", str(out)]) == 0
        )
    ds = xr.open_dataset(nc, engine="h5netcdf")
    assert ds.sizes["change"] == 1 and "EP V116" in str(ds.description.values[0])
    assert str(ds.before_days.values[0]) == "2025-03-01/2025-03-06"
    assert str(ds.after_days.values[0]) == "2025-03-08/2025-03-12"
    move = ds.move_beta_urad.values[0]
    assert np.all(np.abs(move[20:] - 800.0) < 5 * ds.sigma_move_beta_urad.values[0][20:])
    assert ds.significant_beta.values[0][20:].all() and not ds.significant_beta.values[0][:20].any()
    assert ds.move_ground_beta_km.attrs["units"] == "km" and np.all(
        ds.move_ground_beta_km.values[0][20:] > 0.5
    )
    CheckSuite.load_all_available_checkers()
    report = tmp_path / "cf.json"
    ok, errors = ComplianceChecker.run_checker(
        str(nc), ["cf:1.8"], verbose=0, criteria="normal", output_filename=str(report), output_format="json"
    )
    assert ok and not errors, report.read_text()[:3000]
    lines = csv.read_text().splitlines()
    assert len(lines) == 31 and lines[0].startswith("change,scan_position,")
    nc.unlink()  # nothing to export is an answer (exit 0), and no file
    argv = ["export", "--changes", "--config", str(cfg), "--satellite", "j01", "--until", "2025-03-06"]
    assert main([*argv, "--out", str(nc)]) == 0
    assert not nc.exists()


def test_the_metadata_states_the_configured_grid_and_specification(store_with_days, tmp_path):
    from monitor.cli import main

    cfg, _ = store_with_days
    cfg.write_text(cfg.read_text() + "assessment: {half_steps: 8}\nalerts: {spec_km: 2.0}\n")
    out = tmp_path / "j01.nc"
    assert main(["export", "--config", str(cfg), "--satellite", "j01", "--out", str(out)]) == 0
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert "17 x 17 times per FOV" in ds.attrs["summary"] and "21 x 21" not in ds.attrs["summary"]
    assert "The specification is 2 km" in ds.attrs["comment"]


def test_the_defaults_state_the_default_grid_and_specification(store_with_days):
    from monitor.service.outputs.export import to_xarray

    _, store = store_with_days
    ds = to_xarray(store, "j01")
    assert "21 x 21 times per FOV" in ds.attrs["summary"] and "is 1.5 km" in ds.attrs["comment"]


def test_the_export_carries_every_flag_the_table_shows(tmp_path):
    """A FOR whose gain the day could not determine is flagged in the table: the export says so too."""
    from dataclasses import replace

    from monitor.core.result import FLAG_GAIN_UNDETERMINED, FLAG_TOP_HAT, FLAGS
    from monitor.service.outputs.export import FLAG_BITS, to_xarray
    from monitor.service.store.sqlite import Store
    from monitor.simulate.history import day_result

    assert set(FLAG_BITS) == set(FLAGS)
    store = Store(tmp_path / "s.sqlite")
    day = dt.date(2025, 3, 1)
    result = day_result("j01", day, np.random.default_rng(1), 0.0, with_cube=False)
    result.fors[11] = replace(result.fors[11], flags=(FLAG_GAIN_UNDETERMINED, FLAG_TOP_HAT))
    store.save_day(store.begin_run("j01", day), "j01", day, result)
    ds = to_xarray(store, "j01")
    masks = dict(zip(ds.flags.attrs["flag_meanings"].split(), ds.flags.attrs["flag_masks"], strict=True))
    value = int(ds.flags.sel(scan_position=12).values[0])
    assert value == masks["gain_undetermined"] + masks["top_hat"]
    assert int(ds.flags.sel(scan_position=13).values[0]) & masks["gain_undetermined"] == 0
