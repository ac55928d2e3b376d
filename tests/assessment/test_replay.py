"""The estimator on real radiances: the reference implementation's collocation files (ten real NOAA-20
granules, tests/data/real/collocations_j01_20181022, README there) read, checked and assessed, and the
jackknife sigmas honest on them."""

import json

import numpy as np
import pytest

from monitor.assessment.replay import ReplayError, assess_collocations, read_collocation
from monitor.config.assessment import AssessmentConfig
from tests.invoke import ROOT, run_crisgeo

REAL = sorted((ROOT / "tests" / "data" / "real" / "collocations_j01_20181022").glob("*.npz"))


def test_a_collocation_is_read_on_its_centred_square_grid():
    c = read_collocation(REAL[0])
    assert c.file_grid == (17, 15) and c.v_bt_k.shape == (4, 30, 9, 15, 15)
    assert c.step_rad == pytest.approx(455.1e-6, rel=1e-3)
    z = np.load(REAL[0])
    # (beta, alpha) in the file, (alpha, beta) here; the centred 15 of 17 alpha turns
    assert c.v_bt_k[1, 7, 4, 3, 5] == z["cris_v_bt"][5, 4, 1, 7, 4]
    assert c.usable.mean() > 0.9


def test_the_ten_real_granules_give_offsets_and_say_what_they_lack():
    r = assess_collocations(REAL, AssessmentConfig(), "j01")
    assert len(r.fors) == 30 and r.half_steps == 7
    offsets = np.array([[f.d_alpha_urad, f.d_beta_urad] for f in r.fors])
    sigmas = np.array([[f.sigma_alpha_urad, f.sigma_beta_urad] for f in r.fors])
    assert np.isfinite(offsets).all() and np.all(np.abs(offsets) < 7 * 455.1)
    assert np.all(sigmas > 0) and np.median(sigmas) < 200
    assert all(np.isnan(f.in_track_km) and np.isnan(f.total_km) for f in r.fors)
    assert any("km fields empty" in n for n in r.notes) and any("15 x 15" in n for n in r.notes)
    # cone means: the cone's minimum, said per FOR with the cone's floor, and in the notes
    assert all("top_hat" in f.flags for f in r.fors)  # a word on the method, not on reliability
    assert any("top-hat cone's" in n for n in r.notes)
    # the FOV rows show the raw parallax signature of high clouds: the rows ahead turned back against those
    # behind (docs/science.md; cone means cannot be re-collocated)
    rows = np.array([f.fov_rows_alpha_urad for f in r.fors])
    assert np.nanmean(rows) < -200 and np.sum(rows < 0) >= 24
    assert any("no parallax correction" in n for n in r.notes)
    assert all(np.isnan(f.parallax_m_per_k) and np.isnan(f.parallax_height_km) for f in r.fors)
    assert sum(g.n_usable for g in r.granules) > 0.9 * 10 * 4 * 30 * 9
    # the granules' time range from their names, as crisgeo assess prints it with the notes under the table
    assert r.start == "2018-10-22T00:23:59.900000+00:00" and r.end == "2018-10-22T00:29:17.700000+00:00"
    from monitor.cli.output import result_text

    text = result_text(r).splitlines()
    assert text[0] == "j01 2018-10-22T00:23:59Z .. 2018-10-22T00:29:17Z, 10 granules"
    assert any(line.startswith("note: km fields empty") for line in text[33:])
    # the intercalibration on the uniform scenes (warm ocean, a few K wide): no gain determined to 0.1 %,
    # a bias with its sigma, the same at every FOR within a few sigma (docs/science.md: -0.16 K)
    assert all("gain_undetermined" in f.flags and np.isnan(f.gain_pct) for f in r.fors)
    bias = np.array([f.bias_k for f in r.fors])
    assert -0.25 < np.median(bias) < -0.05 and np.all(np.abs(bias - np.median(bias)) < 0.1)


@pytest.mark.parametrize("splits", [6, pytest.param(20, marks=pytest.mark.slow)])
def test_split_halves_agree_within_their_jackknife_sigmas(splits):
    """Honest sigmas on real radiances: 5 granules against the other 5, random splits (twenty with
    ``-m slow``, six by default); the halves'
    offsets differ by more than 2 combined sigmas for at most 12 % of FOR-directions, and the rms of the
    normalised difference lies between 0.75 and 1.3 (the scan bootstrap it replaces: 13-15 %, 1.36-1.41).
    The FOV rows (ahead minus behind) likewise: within 2 combined sigmas for at least 85 %. The
    intercalibration's bias too (>= 88 %), and the halves' median biases never apart by the 0.1 K at which
    calibration_jump fires: a change of scenes alone is not a change of calibration."""
    cfg = AssessmentConfig()
    rng = np.random.default_rng(42)
    z, z_rows, z_bias, apart_k = [], [], [], []
    for _ in range(splits):
        p = rng.permutation(len(REAL))
        a, b = (assess_collocations([REAL[i] for i in half], cfg).fors for half in (p[:5], p[5:]))
        apart_k.append(np.median([f.bias_k for f in a]) - np.median([f.bias_k for f in b]))
        z_bias += [
            (fa.bias_k - fb.bias_k) / np.hypot(fa.sigma_bias_k, fb.sigma_bias_k)
            for fa, fb in zip(a, b, strict=True)
        ]
        for fa, fb in zip(a, b, strict=True):
            for axis in ("alpha", "beta"):
                for name, sigma, out in (
                    (f"d_{axis}_urad", f"sigma_{axis}_urad", z),
                    (f"fov_rows_{axis}_urad", f"sigma_fov_rows_{axis}_urad", z_rows),
                ):
                    diff = getattr(fa, name) - getattr(fb, name)
                    out.append(diff / np.hypot(getattr(fa, sigma), getattr(fb, sigma)))
    z = np.array(z)
    assert np.isfinite(z).mean() > 0.98
    z = z[np.isfinite(z)]
    assert np.mean(np.abs(z) <= 2) >= 0.88
    assert 0.75 <= np.sqrt(np.mean(z**2)) <= 1.3
    # the FOV rows (ahead minus behind), a difference of two estimates of a third of the samples each
    z_rows = np.array(z_rows)
    assert np.isfinite(z_rows).mean() > 0.9
    assert np.mean(np.abs(z_rows[np.isfinite(z_rows)]) <= 2) >= 0.85
    assert np.mean(np.abs(np.array(z_bias)) <= 2) >= 0.88
    assert np.max(np.abs(apart_k)) < 0.1, apart_k


def _bad(tmp_path, **change):
    z = dict(np.load(REAL[0]))
    z.update(change)
    for key in [k for k, v in change.items() if v is None]:
        del z[key]
    path = tmp_path / "bad.npz"
    np.savez(path, **z)
    return path


@pytest.mark.parametrize(
    "change,field,reason",
    [
        ({"cris_c_bt": None}, "cris_c_bt", "missing"),
        ({"alpha": np.array([-1e-3, 0.0, 2e-3])}, "alpha", "uniform"),
        ({"beta": np.linspace(-0.0030, 0.0034, 15)}, "beta", "not zero"),
        ({"cris_c_bt": np.zeros((4, 30, 8))}, "cris_c_bt", "shape"),
        ({"cris_v_bt": np.full((15, 17, 4, 30, 9), 5000.0, np.float32)}, "cris_v_bt", "outside"),
    ],
)
def test_a_bad_file_is_named_with_its_field(tmp_path, change, field, reason):
    path = _bad(tmp_path, **change)
    with pytest.raises(ReplayError, match=f"{path}: {field}: .*{reason}"):
        read_collocation(path)


def test_not_an_archive_is_named(tmp_path):
    path = tmp_path / "x.npz"
    path.write_text("not numpy")
    with pytest.raises(ReplayError, match=f"{path}: \\(file\\): not a NumPy"):
        read_collocation(path)


def test_crisgeo_assess_takes_collocation_files(tmp_path):
    out = tmp_path / "r.json"
    run = run_crisgeo("assess", *map(str, REAL[:3]), "--out", str(out))
    assert run.returncode == 0, run.stderr
    doc = json.loads(out.read_text())
    assert len(doc["fors"]) == 30 and doc["half_steps"] == 7 and doc["notes"]
    bad = run_crisgeo("assess", str(REAL[0]), str(tmp_path))
    assert bad.returncode == 2 and "not both" in bad.stderr
