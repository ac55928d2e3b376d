import json

import numpy as np
import pytest

from monitor.core.errors import DataError
from monitor.sdr import read_file
from monitor.simulate.case import simulate_case
from monitor.simulate.profiles import load_profile, paper_profile
from monitor.simulate.scan_geometry import cris_los_sbf, viirs_bowtie_deleted, viirs_column_geometry


def test_paper_profile_shape():
    a, b = paper_profile()
    assert np.all(np.abs(b[:10]) < 1.0) and b[-1] == pytest.approx(1750.0)
    assert a[0] == pytest.approx(0.051 * 16807.5) and a[-1] == pytest.approx(-0.03 * 16807.5)


def test_profile_from_file_and_bad_profiles(tmp_path):
    f = tmp_path / "p.json"
    f.write_text(
        json.dumps({"fors": [{"for": k, "d_alpha_urad": k, "d_beta_urad": -k} for k in range(1, 31)]})
    )
    a, b = load_profile(str(f))
    assert a[4] == 5 and b[4] == -5
    f.write_text(json.dumps({"d_alpha_urad": [1] * 29, "d_beta_urad": [1] * 30}))
    with pytest.raises(DataError, match="30 finite"):
        load_profile(str(f))
    with pytest.raises(DataError, match="neither"):
        load_profile("papr")


def test_instrument_geometry():
    los = cris_los_sbf()
    beta5 = np.degrees(np.arctan2(los[:, 4, 1], los[:, 4, 2]))
    assert beta5[0] == pytest.approx(-48.33, abs=0.01) and np.allclose(np.diff(beta5), 3.3333)
    theta, t = viirs_column_geometry()
    assert len(theta) == 6400 and np.degrees(theta[-1]) == pytest.approx(56.06, abs=0.05)
    assert np.all(np.diff(t) > 0)
    assert viirs_bowtie_deleted().sum() == 4 * 2 * 2016 + 4 * 2 * 1280


@pytest.fixture(scope="module")
def twin_cases(tmp_path_factory):
    out = {}
    for profile in ("zero", "paper"):
        d = tmp_path_factory.mktemp(profile)
        simulate_case(d, granules=1, profile=profile, seed=11, viirs=False)
        out[profile] = d
    return out


def test_error_goes_into_the_geo_not_the_radiances(twin_cases):
    (g0,) = read_file(next(twin_cases["zero"].glob("GCRSO_*.h5")))
    (g1,) = read_file(next(twin_cases["paper"].glob("GCRSO_*.h5")))
    (s0,) = read_file(next(twin_cases["zero"].glob("SCRIF_*.h5")))
    (s1,) = read_file(next(twin_cases["paper"].glob("SCRIF_*.h5")))
    np.testing.assert_array_equal(s0.radiance_lw, s1.radiance_lw)  # same scene seen along the same true LOS
    shift_km = 6371 * np.hypot(g1.lat_rad - g0.lat_rad, (g1.lon_rad - g0.lon_rad) * np.cos(g0.lat_rad))
    assert shift_km[:, 29].mean() > 3.5 and shift_km[:, 0].mean() < 1.0  # ~4.4 km at FOR 30


def test_deterministic_by_seed(twin_cases, tmp_path):
    simulate_case(tmp_path, granules=1, profile="zero", seed=11, viirs=False)
    (a,) = read_file(next(tmp_path.glob("SCRIF_*.h5")))
    (b,) = read_file(next(twin_cases["zero"].glob("SCRIF_*.h5")))
    np.testing.assert_array_equal(a.radiance_lw, b.radiance_lw)
    truth = json.loads((tmp_path / "truth.json").read_text())
    assert len(truth["fors"]) == 30 and truth["seed"] == 11 and truth["profile"] == "zero"
