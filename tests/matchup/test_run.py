"""The mapping of CrIS FOVs onto four VIIRS bands, against simulated days whose truth is known."""

from __future__ import annotations

import json

import numpy as np
import pytest

from monitor.core.bands import BANDS
from monitor.core.result import MEASURED_FIELDS, AssessmentResult, ForOffset
from monitor.matchup import map_granules
from monitor.simulate.case import simulate_case
from tests.conftest import load_truth, truth_arrays
from tests.invoke import run_crisgeo

xr = pytest.importorskip("xarray")

ALL = tuple(BANDS)
BIAS_K = {"M15": 0.15, "M16": -0.1, "M13": 0.2}
UNIFORM_K = 0.5  # a FOV is uniform in VIIRS where its pixels' BT spread (0.3 K noise included) is below this


@pytest.fixture(scope="module")
def biased(tmp_path_factory):
    """One granule, the M bands only, each with a VIIRS calibration difference injected."""
    out = tmp_path_factory.mktemp("biased")
    simulate_case(
        out, granules=1, seed=3, profile="zero", viirs_bands=("M13", "M15", "M16"), viirs_band_bias_k=BIAS_K
    )
    return out


@pytest.fixture(scope="module")
def four(cases):
    """The shared two-granule case (the paper's error pattern) with all four bands."""
    return cases.get(bands=ALL)[0]


def _uniform_difference(matchup, band: str, warm_k: float | None = None) -> np.ndarray:
    b = matchup.bands.index(band)
    d = matchup.values["cris_bt_k"][b] - matchup.values["viirs_bt_k"][b]
    keep = matchup.values["viirs_bt_std_k"][b] < UNIFORM_K
    if warm_k is not None:
        keep &= matchup.values["viirs_bt_k"][b] > warm_k
    return d[keep & np.isfinite(d)]


def test_each_band_reads_the_calibration_difference_injected_in_it(biased):
    matchup, cost = map_granules([biased], ("M13", "M15", "M16"))
    assert matchup.bands == ("M13", "M15", "M16") and matchup.geolocation == "operational"
    for band, bias in BIAS_K.items():
        d = _uniform_difference(matchup, band, BANDS[band].min_scene_k)
        assert d.size > 100, band
        assert abs(np.median(d) + bias) < 0.03, (band, np.median(d))
        assert np.std(d) < 0.1, band
    assert set(cost.read_s) == {"M13", "M15", "M16"} and all(v > 0 for v in cost.bytes_read.values())


def test_a_day_without_a_difference_reads_zero_in_every_band(four):
    matchup, _ = map_granules([four])
    assert matchup.bands == ALL
    for band in ALL:
        d = _uniform_difference(matchup, band, BANDS[band].min_scene_k)
        assert d.size > 100 and abs(np.median(d)) < 0.1, (band, np.median(d))
    pixels = matchup.values["viirs_pixels"]
    i5, m15 = pixels[ALL.index("I5")], pixels[ALL.index("M15")]
    # an I-band pixel is half an M-band pixel each way: four times the pixels in a FOV
    assert 3.5 < np.median(i5[i5 > 0] / m15[i5 > 0]) < 4.5
    assert np.nanmedian(matchup.values["viirs_valid_fraction"]) > 0.95


def _truth_result(case_dir) -> AssessmentResult:
    """An assessment result carrying the case's true offsets: the FOVs placed where they really look."""
    truth = load_truth(case_dir)
    d_alpha, d_beta = truth_arrays(truth)
    fors = [
        ForOffset.from_dict(
            {
                **dict.fromkeys(MEASURED_FIELDS),
                "for": k + 1,
                "d_alpha_urad": float(a),
                "d_beta_urad": float(b),
            }
        )
        for k, (a, b) in enumerate(zip(d_alpha, d_beta, strict=True))
    ]
    return AssessmentResult(truth["satellite"], truth["start"], truth["start"], fors)


def test_the_assessed_geolocation_brings_crIS_and_viirs_together(four):
    """The case carries the paper's error pattern (FORs 26-30 beyond 4 km): placed where CrIS really looks,
    every FOV's CrIS and VIIRS agree better than where GEO puts them."""
    operational, _ = map_granules([four], ("I5", "M15"))
    assessed, _ = map_granules([four], ("I5", "M15"), offsets=_truth_result(four))
    assert assessed.geolocation == "assessed" and operational.geolocation == "operational"
    assert not np.allclose(assessed.latitude_deg, operational.latitude_deg)
    for b in range(2):
        rms = []
        for m in (operational, assessed):
            d = m.values["cris_bt_k"][b] - m.values["viirs_bt_k"][b]
            rms.append(float(np.sqrt(np.nanmean(d**2))))
        assert rms[1] < 0.5 < rms[0], rms


def test_the_file_is_cf_netcdf_that_xarray_reads(biased, tmp_path):
    out = tmp_path / "map.nc"
    done = run_crisgeo("map", biased, "--out", out, "--bands", "M15,M16")
    assert done.returncode == 0, done.stderr
    assert "operational geolocation, nominal response" in done.stdout
    ds = xr.open_dataset(out, engine="h5netcdf")
    assert list(ds.band.values) == ["M15", "M16"]
    assert ds.viirs_bt_k.dims == ("band", "scan", "scan_position", "fov")
    assert ds.sizes["scan"] == 4 and ds.sizes["scan_position"] == 30 and ds.sizes["fov"] == 9
    assert ds.viirs_bt_k.attrs["units"] == "K" and ds.latitude.attrs["standard_name"] == "latitude"
    assert ds.attrs["geolocation"] == "operational" and "ACDD-1.3" in ds.attrs["Conventions"]
    assert float(ds.cris_bt_k.sel(band="M15").mean()) > 200


def test_the_netcdf_passes_the_cf_checker(biased, tmp_path):
    cc = pytest.importorskip("compliance_checker.runner")
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    matchup, _ = map_granules([biased], ("M15",))
    out = matchup.write(tmp_path / "m.nc")
    CheckSuite.load_all_available_checkers()
    report = tmp_path / "cf.json"
    ok, errors = ComplianceChecker.run_checker(
        str(out), ["cf:1.8"], verbose=0, criteria="normal", output_filename=str(report), output_format="json"
    )
    assert cc is not None and ok and not errors, report.read_text()[:3000]


def test_bad_offsets_and_bands_are_bad_input(biased, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"satellite": "j01"}))
    done = run_crisgeo("map", biased, "--out", tmp_path / "x.nc", "--offsets", bad)
    assert done.returncode == 2 and str(bad) in done.stderr
    done = run_crisgeo("map", biased, "--out", tmp_path / "x.nc", "--bands", "M14")
    assert done.returncode == 2 and "M14" in done.stderr
    assert not (tmp_path / "x.nc").exists()
