"""The simulator's four VIIRS bands: each on its own grid, scenes that differ between bands as real ones do,
and a calibration difference injected in one band only."""

from __future__ import annotations

import numpy as np
import pytest

from monitor.core.bands import BANDS
from monitor.core.errors import DataError
from monitor.sdr import read_file
from monitor.simulate.case import SimulationSpec


@pytest.fixture(scope="module")
def bt(cases):
    out, _, _ = cases.get(bands=tuple(BANDS))
    return {
        b: read_file(sorted(out.glob(f"{BANDS[b].sdr_prefix}_*.h5"))[0])[0].bt_k
        for b in ("M13", "M15", "M16")
    }


def test_a_warm_moist_clear_scene_is_colder_in_m16_than_in_m15(bt):
    warm = bt["M15"] > 290
    assert warm.sum() > 10_000
    assert 0.5 < np.nanmedian(bt["M15"][warm] - bt["M16"][warm]) < 3.0


def test_cold_cloud_tops_read_alike_in_every_band(bt):
    cold = bt["M15"] < 240
    assert cold.sum() > 1_000
    for band in ("M13", "M16"):
        assert abs(np.nanmedian(bt[band][cold] - bt["M15"][cold])) < 1.5, band


def test_bands_and_differences_are_checked():
    with pytest.raises(DataError, match="M14"):
        SimulationSpec(granules=1, viirs_bands=("I5", "M14"))
    with pytest.raises(DataError, match="within"):
        SimulationSpec(granules=1, viirs_band_bias_k={"M15": 50.0})
