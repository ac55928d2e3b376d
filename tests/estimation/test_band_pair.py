"""The offsets read in M15 beside I5's: the paired jackknife sees what both bands share, the flag what they do
not."""

from __future__ import annotations

import math

import numpy as np
import pytest

from monitor.core.result import FLAG_BANDS_DIFFER, FLAG_FLAT, AssessmentResult, ForOffset, ForReplicates
from monitor.estimation.band_pair import DIFFER_SIGMAS, paired_sigma_urad, with_second_band
from monitor.estimation.jackknife import replicate_sigma


def _replicates(alpha, beta, names=None, factor=1.0):
    names = names or [f"g{i}" for i in range(len(alpha))]
    return ForReplicates(
        tuple((n, n) for n in names), np.asarray(alpha, float), np.asarray(beta, float), factor
    )


def test_what_both_bands_share_leaves_the_paired_sigma():
    """Scenes shared by both bands move both bands' replicates alike: the paired sigma is that of the
    bands' own parts, far below the two sigmas in quadrature."""
    rng = np.random.default_rng(3)
    shared = rng.normal(0, 20, (8, 2))
    own_i5, own_m15 = rng.normal(0, 2, (8, 2)), rng.normal(0, 2, (8, 2))
    i5 = _replicates(*(shared + own_i5).T)
    m15 = _replicates(*(shared + own_m15).T)
    sigma = np.array(paired_sigma_urad(i5, m15))
    alone = replicate_sigma(shared + own_i5)
    assert np.all(sigma < alone / 3)
    np.testing.assert_allclose(sigma, replicate_sigma(own_m15 - own_i5))


def test_replicates_pair_by_the_granules_they_leave_out():
    i5 = _replicates([1.0, 2.0, 3.0, 4.0, 5.0], [0.0] * 5, ["a", "b", "c", "d", "e"])
    # M15 lacks granule c, and lists the others in another order: paired by name
    m15 = _replicates([5.5, 1.5, 4.5, 2.5], [0.0] * 4, ["e", "a", "d", "b"])
    alpha, _ = paired_sigma_urad(i5, m15)
    assert alpha == pytest.approx(0.0, abs=1e-12)  # every common pair differs by the same 0.5


def test_too_few_common_granules_give_no_sigma():
    i5 = _replicates([1.0, 2.0, 3.0, 4.0], [0.0] * 4, ["a", "b", "c", "d"])
    m15 = _replicates([1.0, 2.0, 3.0, 4.0], [0.0] * 4, ["a", "b", "c", "x"])
    assert all(math.isnan(s) for s in paired_sigma_urad(i5, m15))
    assert all(math.isnan(s) for s in paired_sigma_urad(i5, None))


def test_the_larger_correlation_factor_counts():
    i5 = _replicates([1.0, 2.0, 3.0, 4.0], [1.0, 3.0, 2.0, 0.0], factor=1.0)
    m15 = _replicates([0.0, 0.0, 0.0, 0.0], [0.0] * 4, factor=1.5)
    one = paired_sigma_urad(i5, _replicates([0.0] * 4, [0.0] * 4))
    np.testing.assert_allclose(paired_sigma_urad(i5, m15), 1.5 * np.array(one))


def _day(alphas, sigma_alpha, flags=(), reps=None):
    fors = [
        ForOffset(for_index=k + 1, d_alpha_urad=a, d_beta_urad=0.0, sigma_alpha_urad=sigma_alpha,
                  sigma_beta_urad=sigma_alpha, in_track_km=0.0, cross_track_km=0.0, total_km=0.0,
                  sigma_in_track_km=0.0, sigma_cross_track_km=0.0, n_samples=100, cost_min_k=0.1,
                  cost_zero_k=0.2, flags=tuple(flags))
        for k, a in enumerate(alphas)
    ]  # fmt: skip
    return AssessmentResult("j01", "", "", fors, replicates=reps or [None] * len(fors))


def test_the_m15_offsets_sit_beside_i5s_and_a_difference_beyond_doubt_is_flagged():
    names = [f"g{i}" for i in range(6)]
    spread = np.array([-2.0, -1.0, 0.0, 1.0, 2.0, 0.0])  # the same granules move both bands alike
    i5 = _day([100.0, 100.0], 5.0, reps=[_replicates(100 + spread, spread, names)] * 2)
    own = np.array([0.5, -0.5, 0.5, -0.5, 0.0, 0.0])  # M15's own scatter: a paired sigma under 1 urad
    m15 = _day(
        [101.0, 130.0],
        8.0,
        reps=[_replicates(101 + spread + own, spread, names), _replicates(130 + spread + own, spread, names)],
    )
    out = with_second_band(i5, m15)
    first, second = out.fors
    assert (first.d_alpha_urad, first.d_alpha_urad_M15, first.sigma_alpha_urad_M15) == (100.0, 101.0, 8.0)
    assert second.m15_minus_i5_alpha_urad == 30.0
    sigma = second.sigma_m15_minus_i5_alpha_urad
    assert 0 < sigma < 1.5
    assert 30.0 > DIFFER_SIGMAS * sigma and FLAG_BANDS_DIFFER in second.flags
    assert abs(first.m15_minus_i5_alpha_urad) < DIFFER_SIGMAS * first.sigma_m15_minus_i5_alpha_urad
    assert FLAG_BANDS_DIFFER not in first.flags
    assert second.reliable  # the I5 offset stays usable


def test_an_unreliable_fors_difference_is_not_flagged():
    names = [f"g{i}" for i in range(5)]
    reps = [_replicates(np.arange(5.0), np.zeros(5), names)]
    i5 = _day([0.0], 5.0, flags=(FLAG_FLAT,), reps=reps)
    m15 = _day([500.0], 5.0, reps=reps)
    (f,) = with_second_band(i5, m15).fors
    assert f.m15_minus_i5_alpha_urad == 500.0 and FLAG_BANDS_DIFFER not in f.flags


def test_the_fields_are_the_results_own_and_read_back_from_its_json():
    i5 = _day([10.0], 2.0)
    out = with_second_band(i5, _day([12.0], 3.0))
    back = AssessmentResult.from_json(out.to_json())
    f = back.fors[0]
    assert (f.d_alpha_urad_M15, f.sigma_alpha_urad_M15, f.m15_minus_i5_alpha_urad) == (12.0, 3.0, 2.0)
    assert math.isnan(f.sigma_m15_minus_i5_alpha_urad)  # no replicates: no paired sigma
    assert back.replicates == []  # the day's own, never written
