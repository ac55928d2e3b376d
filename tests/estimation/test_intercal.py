"""The CrIS-VIIRS intercalibration at the optimum: the fit of bias and gain, its jackknife, the BT bins."""

import numpy as np
import pytest

from monitor.core.constants import CALIBRATION_BIN_K, CALIBRATION_CURVATURE_SPAN_K, CALIBRATION_REFERENCE_K
from monitor.estimation.intercal import difference_bins, fit_difference, intercalibrate
from monitor.estimation.jackknife import Jackknife


def _pair(rng, n=400, bias_k=0.8, gain=-0.02, curvature_k=0.3, noise_k=0.0):
    """CrIS and VIIRS BT (K) of *n* scenes, CrIS = VIIRS + the law of monitor/estimation/intercal.py +
    noise."""
    v = rng.normal(275.0, 12.0, n)
    x = v - CALIBRATION_REFERENCE_K
    law = bias_k + gain * x + curvature_k * (x / CALIBRATION_CURVATURE_SPAN_K) ** 2
    return v + law + rng.normal(0.0, noise_k, n), v


def test_the_law_is_recovered_exactly_without_noise():
    c, v = _pair(np.random.default_rng(1))
    assert fit_difference(c, v) == pytest.approx([0.8, -0.02, 0.3], abs=1e-9)
    # a straight law: no curvature found; one BT for every scene: no fit, not a number from nothing
    c, v = _pair(np.random.default_rng(1), curvature_k=0.0)
    assert fit_difference(c, v)[2] == pytest.approx(0.0, abs=1e-9)
    assert np.isnan(fit_difference(np.full(50, 281.0), np.full(50, 280.0))).all()


def test_counts_weigh_like_repeated_samples():
    rng = np.random.default_rng(2)
    c, v = _pair(rng, n=50, noise_k=0.3)
    counts = rng.integers(0, 3, (4, 50)).astype(float)
    fits = fit_difference(c, v, counts)
    for k in range(4):
        rep = np.repeat(np.arange(50), counts[k].astype(int))
        assert fits[k] == pytest.approx(fit_difference(c[rep], v[rep]), rel=1e-9)
    # one V per replicate (each at its own optimum): each row its own fit
    shifted = v[None] + rng.normal(0.0, 0.5, (4, 50))
    rows = fit_difference(c, shifted, counts)
    for k in range(4):
        rep = np.repeat(np.arange(50), counts[k].astype(int))
        assert rows[k] == pytest.approx(fit_difference(c[rep], shifted[k][rep]), rel=1e-9)


def test_the_jackknife_sigma_matches_the_scatter_of_independent_draws():
    """The jackknife's sigma of the fit over 80 groups of samples is the spread over fresh noise (within
    25 %)."""
    rng = np.random.default_rng(3)
    fits = np.array([fit_difference(*_pair(rng, noise_k=0.3)) for _ in range(200)])
    c, v = _pair(rng, noise_k=0.3)
    jack = Jackknife.of(np.arange(len(c)) % 80, np.zeros(len(c)))
    cal = intercalibrate(c, v, jack)
    assert cal.sigma_bias_k == pytest.approx(fits[:, 0].std(), rel=0.25)
    assert cal.sigma_gain_pct == pytest.approx(100 * fits[:, 1].std(), rel=0.25)
    assert cal.sigma_curvature_k == pytest.approx(fits[:, 2].std(), rel=0.25)
    assert cal.bias_k == pytest.approx(0.8, abs=4 * cal.sigma_bias_k)
    assert cal.curvature_k == pytest.approx(0.3, abs=4 * cal.sigma_curvature_k)
    assert np.isnan(intercalibrate(c[:3], v[:3]).bias_k)  # too few samples: no fit
    warm = v > 285.0  # samples that do not reach 280 K: no value there from extrapolation
    assert np.isnan(intercalibrate(c[warm], v[warm], Jackknife(jack.counts[:, warm])).bias_k)
    near = np.abs(v - 282.0) < 6.0  # around 280 K but only 12 K wide
    assert np.isnan(intercalibrate(c[near], v[near]).gain_pct)


def test_bins_are_the_difference_against_the_cris_bt():
    rng = np.random.default_rng(4)
    c = rng.uniform(215.0, 305.0, 2000)
    v = c - 0.01 * (c - 250.0) + rng.normal(0.0, 0.2, c.size)
    c[::97] = np.nan  # never counted
    bins = difference_bins(c, v)
    ok = np.isfinite(c)
    assert [b.low_k for b in bins] == [210.0 + CALIBRATION_BIN_K * k for k in range(10)]
    assert sum(b.n for b in bins) == ok.sum()
    for b in bins:
        sel = ok & (c >= b.low_k) & (c < b.low_k + CALIBRATION_BIN_K)
        assert b.n == sel.sum()
        assert b.mean_k == pytest.approx(np.mean(c[sel] - v[sel]))
        assert b.std_k == pytest.approx(np.std(c[sel] - v[sel], ddof=1))
    assert difference_bins([], []) == []
