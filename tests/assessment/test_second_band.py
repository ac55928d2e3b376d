"""The geolocation assessed in M15 as in I5: the cones collocated on the M grid (their sums smoothed over the
perturbations), a day without M15 kept."""

from __future__ import annotations

import numpy as np
import pytest

from monitor.assessment.assess import DayAssessment, collocate_run, in_second_band
from monitor.config.assessment import AssessmentConfig
from monitor.core.bands import BANDS
from monitor.core.result import AssessmentResult
from monitor.sdr.pairing import plan

ALL = tuple(BANDS)


@pytest.fixture(scope="module")
def four_bands(cases):
    """The plan of a simulated two-granule day in every band."""
    out, _, _ = cases.get(bands=ALL)
    return plan([out], bands=ALL)


def _collocated(case, band):
    cris = case.cris[:1]
    viirs = {g.key: case.cover(g, band) for g in cris}
    pool = case.viirs_all if band == "I5" else case.bands[band]
    (samples,), skipped = collocate_run(cris, viirs, pool, "j01", AssessmentConfig(parallax=False), band=band)
    assert not skipped
    return samples


def test_the_m_grid_cones_cover_the_fovs_and_see_the_scenes_i5_sees(four_bands):
    """On the M grid's 16-detector scans (a quarter of the pixels) the cones find as many FOVs fully covered
    as on the I grid, and their unperturbed VIIRS BT follows the scenes as I5's does."""
    i5, m15 = _collocated(four_bands, "I5"), _collocated(four_bands, "M15")
    assert m15.usable.sum() >= 0.97 * i5.usable.sum() > 0
    both = i5.usable & m15.usable
    centre = i5.bt_viirs_k.shape[-1] // 2
    a = i5.bt_viirs_k[..., centre, centre][both]
    b = m15.bt_viirs_k[..., centre, centre][both]
    assert np.std(a) > 2.0  # scenes with contrast
    assert np.corrcoef(a, b)[0, 1] > 0.98
    # the bands' CrIS minus VIIRS alike: what the two bands' different spectra leave is a level, not scenes
    d_i5 = i5.bt_viirs_k[..., centre, centre][both] - i5.bt_cris_k[both]
    d_m15 = m15.bt_viirs_k[..., centre, centre][both] - m15.bt_cris_k[both]
    assert np.std(d_m15 - d_i5) < 0.25 * np.std(a)


def _roughness_k(samples):
    """The RMS second difference (K) of the cones' VIIRS BT across the perturbation grid, both axes."""
    bt = np.asarray(samples.bt_viirs_k)[samples.usable]
    along = bt[:, 2:, :] - 2 * bt[:, 1:-1, :] + bt[:, :-2, :]
    across = bt[:, :, 2:] - 2 * bt[:, :, 1:-1] + bt[:, :, :-2]
    return float(np.sqrt(np.nanmean(along**2) + np.nanmean(across**2)))


def test_the_m_grid_cones_move_as_smoothly_as_the_i_grids(four_bands):
    """Smoothed over the perturbations, the M grid's cones gain and lose pixels no more abruptly than the I
    grid's: the perturbed cones' BT is no rougher than I5's (unsmoothed, about four times as rough)."""
    rough_i5 = _roughness_k(_collocated(four_bands, "I5"))
    rough_m15 = _roughness_k(_collocated(four_bands, "M15"))
    assert 0 < rough_m15 < 1.5 * rough_i5


def test_a_day_without_m15_keeps_its_i5_offsets_and_says_why(four_bands, cases):
    _, _, result = cases.get()  # a day assessed in I5
    assert isinstance(result, AssessmentResult)
    case = plan([cases.get()[0]])  # its granules, no M15 among them
    cfg = AssessmentConfig(bands=["I5", "M15"])
    out = in_second_band(case, result, cfg)
    assert [f.d_alpha_urad for f in out.fors] == [f.d_alpha_urad for f in result.fors]
    assert all(np.isnan(f.d_alpha_urad_M15) for f in out.fors)
    assert any("no offsets in M15" in n and "no VIIRS M15 granule covers it" in n for n in out.notes)
    assert in_second_band(case, result, AssessmentConfig()) is result  # M15 not configured: nothing done


def test_the_geolocation_is_read_in_a_long_wave_band_only():
    with pytest.raises(ValueError, match="M13"):
        DayAssessment("j01", AssessmentConfig(), band="M13")
