"""The CrIS-VIIRS intercalibration at the optimum: the errors-in-variables fit on the scenes the collocation
cannot move, its variance model, its jackknife, the BT bins."""

import numpy as np
import pytest

from monitor.core.constants import (
    CALIBRATION_BIN_K,
    CALIBRATION_CURVATURE_SPAN_K,
    CALIBRATION_REFERENCE_K,
    DEFAULT_STEP_RAD,
)
from monitor.estimation.intercal import (
    GAIN_RESOLUTION_PCT,
    REACH_RAD,
    collocation_spread_k,
    difference_bins,
    fit_difference,
    intercalibrate,
    reach_steps,
    variance_scale,
)
from monitor.estimation.jackknife import MAX_GROUPS, Jackknife, t_factor


def _law(v, bias_k=0.8, gain=-0.02, curvature_k=0.3):
    x = v - CALIBRATION_REFERENCE_K
    return bias_k + gain * x + curvature_k * (x / CALIBRATION_CURVATURE_SPAN_K) ** 2


def _day(rng, n=600, noise_k=0.03, edges=0.5, **law):
    """*n* scenes, a share *edges* of them cloud edges: the cone mean V misses what CrIS saw by a
    collocation error up to the edge's spread (uniform scenes: a spread at the noise). Returns C, V and
    the spreads; CrIS = the true scene + the law + noise."""
    truth = rng.normal(270.0, 20.0, n)
    edge = rng.random(n) < edges
    spread = np.where(edge, rng.uniform(1.0, 6.0, n), rng.uniform(0.005, 0.03, n))
    # the cone mean leans towards the scene's mean at an edge, the error growing with the departure; a
    # uniform scene's is its noise
    lean = -(truth - 270.0) / 20.0 * spread * rng.uniform(0.3, 1.0, n)
    v = truth + np.where(edge, lean, rng.normal(0.0, 1.0, n) * spread / 2)
    c = truth + _law(truth, **law) + rng.normal(0.0, noise_k, n)
    return c, v, spread


def test_the_reach_covers_the_response_beyond_the_cone():
    assert REACH_RAD == pytest.approx(np.radians(1.238) / 2 - np.radians(0.963) / 2, rel=0.01)
    k = reach_steps(DEFAULT_STEP_RAD)
    assert (k - 1) * DEFAULT_STEP_RAD < REACH_RAD <= k * DEFAULT_STEP_RAD


def test_the_spread_is_the_cone_means_largest_change_within_the_reach():
    d = np.zeros((3, 21, 21))
    d[0, 10, 14] = 0.5  # 4 steps from the optimum (10, 10): within a reach of 4, not of 3
    d[1, 0, 0] = 9.0  # far away: never seen
    d[2, 12, 9] = np.nan  # a turn without a cone mean: the sample weighs nothing
    assert collocation_spread_k(d, 10, 10, 4) == pytest.approx([0.5, 0.0, np.inf])
    assert collocation_spread_k(d, 10, 10, 3)[0] == 0.0
    assert collocation_spread_k(d, 1, 1, 2)[1] == 9.0  # clipped at the grid's border


def test_the_law_is_recovered_exactly_without_noise():
    rng = np.random.default_rng(1)
    v = rng.normal(275.0, 12.0, 400)
    beta, cov = fit_difference(v + _law(v), v, np.zeros(400), (0.01, 1.0))
    assert beta == pytest.approx([0.8, -0.02, 0.3], abs=1e-9)
    assert np.isfinite(cov).all()
    assert np.isnan(
        fit_difference(np.full(50, 281.0), np.full(50, 280.0), np.zeros(50), (0.01, 1.0))[0]
    ).all()


def test_counts_weigh_like_repeated_samples():
    rng = np.random.default_rng(2)
    c, v, s = _day(rng, n=60)
    counts = rng.integers(0, 3, (4, 60)).astype(float)
    fits, _ = fit_difference(c, v, s, (0.03, 0.5), counts)
    for k in range(4):
        rep = np.repeat(np.arange(60), counts[k].astype(int))
        assert fits[k] == pytest.approx(fit_difference(c[rep], v[rep], s[rep], (0.03, 0.5))[0], rel=1e-9)


def test_the_collocation_is_not_read_as_calibration():
    """Half the scenes cloud edges whose cone mean leans towards the mean scene: least squares on every
    scene reads a gain diluted by about -var(e)/var(V); the weighted fit on what the collocation cannot
    move recovers the law (other seeds than the first give the same within the sigmas)."""
    for seed in (3, 4, 5):
        c, v, s = _day(np.random.default_rng(seed), gain=0.0, curvature_k=0.0, bias_k=0.1)
        plain = np.polyfit(v - CALIBRATION_REFERENCE_K, c - v, 1)[0]
        assert plain > 0.02  # the dilution: V's spread squeezed by the edges
        scale = variance_scale(c, v, s, 3)
        beta, cov = fit_difference(c, v, s, scale)
        assert abs(beta[1]) < 4 * np.sqrt(cov[1, 1]) and np.sqrt(cov[1, 1]) < GAIN_RESOLUTION_PCT / 100
        assert beta[0] == pytest.approx(0.1, abs=0.02)


def test_the_variance_model_is_found_from_the_residuals():
    """sigma_0 is the uniform scenes' noise, kappa how much of the spread shows as error (within 30 %)."""
    rng = np.random.default_rng(6)
    n = 3000
    v = rng.normal(270.0, 15.0, n)
    s = np.where(rng.random(n) < 0.5, rng.uniform(0.5, 3.0, n), 0.0)
    c = v + _law(v) + rng.normal(0.0, 0.05, n) + rng.normal(0.0, 1.0, n) * 0.2 * s
    noise, kappa = variance_scale(c, v, s)
    # the residual's variance is sigma_0^2 (C) + sigma_0^2 (V) for a uniform scene: 0.05 / sqrt(2) each
    assert noise == pytest.approx(0.05 / np.sqrt(2), rel=0.3)
    assert kappa == pytest.approx(0.2, rel=0.3)


def test_the_jackknife_sigma_matches_the_scatter_of_independent_days():
    """The jackknife's sigma of the bias and gain from 80 granules (left out in MAX_GROUPS runs), its mean
    over ten days, is the spread over fresh days times the t's factor for the runs (within 20 %)."""
    rng = np.random.default_rng(7)
    cals = [intercalibrate(*_day(rng)) for _ in range(60)]
    fits = []
    for _ in range(10):
        c, v, s = _day(rng)
        jack = Jackknife.of(np.arange(len(c)) % 80, np.zeros(len(c)))
        fits.append(intercalibrate(c, v, s, jack))
    assert jack.groups == MAX_GROUPS
    factor = t_factor(MAX_GROUPS - 1)
    for name, sigma in (("bias_k", "sigma_bias_k"), ("gain_pct", "sigma_gain_pct")):
        spread = np.std([getattr(x, name) for x in cals])
        assert np.mean([getattr(x, sigma) for x in fits]) == pytest.approx(factor * spread, rel=0.2)
    cal = fits[-1]
    assert cal.bias_k == pytest.approx(0.8, abs=4 * cal.sigma_bias_k)
    assert cal.gain_pct == pytest.approx(-2.0, abs=4 * cal.sigma_gain_pct)
    assert np.isnan(intercalibrate(c[:3], v[:3], s[:3]).bias_k)  # too few samples: no fit


def test_scenes_of_one_temperature_give_a_bias_and_no_gain():
    """Warm ocean alone (a few K): the gain is undetermined (NaN, so flagged), the bias the scenes' mean
    difference, with its sigma."""
    rng = np.random.default_rng(8)
    v = rng.normal(293.0, 1.0, 300)
    c = v + 0.2 + rng.normal(0.0, 0.05, 300)
    jack = Jackknife.of(np.arange(300) % 10, np.zeros(300))
    cal = intercalibrate(c, v, np.full(300, 0.02), jack)
    assert cal.gain_undetermined and np.isnan(cal.curvature_k) and np.isnan(cal.sigma_gain_pct)
    assert cal.bias_k == pytest.approx(0.2, abs=4 * cal.sigma_bias_k) and 0 < cal.sigma_bias_k < 0.02


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
