"""VIIRS pixels where they are: terrain-corrected GITCO pixels at (lat, lon, Height), not on the ellipsoid."""

import numpy as np
import pytest

from monitor.assessment.assess import assess_paths
from monitor.collocation import swath
from monitor.config.assessment import AssessmentConfig
from monitor.sdr import read_file
from monitor.simulate.case import simulate_case
from tests.conftest import truth_arrays


@pytest.fixture(scope="module")
def mountains(tmp_path_factory):
    """One CrIS granule over 1-4 km terrain (about 40 % of its FOVs above 500 m)."""
    out = tmp_path_factory.mktemp("terrain")
    truth = simulate_case(out, granules=1, profile="paper", seed=1, terrain=True)
    return out, truth


def _errors(result, truth):
    ta, tb = truth_arrays(truth)
    ok = np.array([f.reliable for f in result.fors])
    return (np.array([f.d_alpha_urad for f in result.fors]) - ta)[ok], (
        np.array([f.d_beta_urad for f in result.fors]) - tb
    )[ok]


def test_simulated_terrain_in_the_files(mountains):
    out, truth = mountains
    (gcrso,) = read_file(next(out.glob("GCRSO_*.h5")))
    (gitco,) = read_file(next(out.glob("GITCO_*.h5")))
    assert (
        truth["terrain"] and (gcrso.height_m > 500).mean() > 0.25
    )  # GCRSO reports the height (h = 0 points)
    assert np.nanmax(gitco.height_m) > 2500 and abs(np.nanmin(gitco.height_m)) < 1e-3


def test_assessment_needs_the_height(mountains, monkeypatch):
    out, truth = mountains
    cfg = AssessmentConfig(uncertainty=False)
    ea, eb = _errors(assess_paths([out], cfg), truth)
    assert len(ea) >= 25 and max(np.abs(ea).max(), np.abs(eb).max()) < 100
    assert np.sqrt(np.mean(np.r_[ea, eb] ** 2)) < 40
    real = swath.swath_piece

    def on_ellipsoid(lat, lon, height, *args, **kw):
        halo = [None if h is None else (h[0], h[1], np.zeros_like(h[2])) for h in args[3:5]]
        return real(lat, lon, np.zeros_like(height), *args[:3], *halo, **kw)

    monkeypatch.setattr(swath, "swath_piece", on_ellipsoid)
    ea0, eb0 = _errors(assess_paths([out], cfg), truth)
    assert max(np.abs(ea0).max(), np.abs(eb0).max()) > 300  # ~0.5 mrad per km of terrain at the scan edge
