"""The ideal views' bench rebuilds the case's own scene from its truth: on a flat day every view of a GEO
point is VIIRS's own BT but for the noise of the two draws (the scene of another seed is kelvins off)."""

import numpy as np
import pytest

from monitor.collocation.render import VIEW_ALPHA_RAD
from monitor.core.constants import VIIRS_DETECTORS
from monitor.sdr import read_file
from studies.ideal_views import IdealViews, simulator_of
from tests.conftest import load_truth

SCANS = slice(20, 22)
COLUMNS = slice(3000, 3200)


def _views(case, truth):
    geo_file = next(case.glob("GITCO_*.h5"))
    sdr_file = next(case.glob("SVI05_*.h5"))
    geo = read_file(geo_file, kinds=("viirs_geo",))[0]
    sdr = read_file(sdr_file, kinds=("viirs_sdr",))[0]
    views = IdealViews(simulator_of(truth))(
        geo.lat_rad, geo.lon_rad, geo.height_m, sdr.bt_k, sdr.good, geo.sc_position_m, geo.sc_velocity_m_s,
        VIEW_ALPHA_RAD, 0.0, SCANS, COLUMNS,
    )  # fmt: skip
    rows = slice(SCANS.start * VIIRS_DETECTORS, SCANS.stop * VIIRS_DETECTORS)
    return views[:, rows, COLUMNS], sdr.bt_k[rows, COLUMNS], views


@pytest.mark.parametrize("seed_shift", [0, 1])
def test_the_case_s_own_scene_is_seen_again_and_only_it(cases, seed_shift):
    case, _, _ = cases.get()
    truth = load_truth(case)
    truth["seed"] += seed_shift
    inside, bt_k, whole = _views(case, truth)
    diff = np.abs(inside - bt_k[None])
    assert np.isfinite(inside).mean() > 0.9 and np.isnan(whole[:, :100]).all()
    if seed_shift == 0:  # two draws of 0.3 K noise: |difference| has a median of ~0.29 K
        assert np.nanmedian(diff) < 0.4 and np.nanpercentile(diff, 95) < 1.5, np.nanpercentile(diff, [50, 95])
    else:
        assert np.nanmedian(diff) > 1.0, np.nanmedian(diff)
