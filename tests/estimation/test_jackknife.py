"""The delete-one-granule jackknife: the standard error of a mean exactly (with the t's small-sample
factor), granules as groups from four, scans below; errors over their sigma of unit variance."""

import numpy as np
import pytest

from monitor.estimation.jackknife import MIN_GRANULES, Jackknife


def test_the_jackknife_of_a_mean_is_its_standard_error():
    rng = np.random.default_rng(1)
    granule = np.repeat(np.arange(6), 20)
    x = rng.normal(0.0, 1.0, 6)[granule] + rng.normal(0.0, 0.1, granule.size)
    jack = Jackknife.of(granule, np.zeros(granule.size))
    assert jack.groups == 6
    replicates = jack.counts @ x / jack.counts.sum(axis=1)
    means = np.bincount(granule, x) / 20
    nu = 5
    assert jack.sigma(replicates) == pytest.approx(means.std(ddof=1) / np.sqrt(6) * np.sqrt(nu / (nu - 2)))


@pytest.mark.parametrize("granules", [5, 8, 14])
def test_errors_over_their_sigma_have_unit_variance(granules):
    """Means of G granules of heavy scene-to-scene scatter, 4000 days: (mean - truth) / sigma has variance
    1 within 6 %, and |error| <= 2 sigma for 93-97 % (a t's 2-sigma coverage at unit variance)."""
    rng = np.random.default_rng(granules)
    granule = np.repeat(np.arange(granules), 10)
    z = []
    for _ in range(4000):
        x = rng.normal(0.0, 1.0, granules)[granule] + rng.normal(0.0, 0.3, granule.size)
        jack = Jackknife.of(granule, np.zeros(granule.size))
        replicates = jack.counts @ x / jack.counts.sum(axis=1)
        z.append(x.mean() / jack.sigma(replicates))
    z = np.array(z)
    assert np.mean(z**2) == pytest.approx(1.0, abs=0.06)
    assert 0.93 <= np.mean(np.abs(z) <= 2) <= 0.975


def test_the_groups_are_granules_from_three_else_scans():
    scan = np.tile(np.repeat(np.arange(4), 9), 2)
    two = Jackknife.of(np.repeat([0, 1], 36), scan)
    assert two.groups == 8  # two granules of four scans: the scans
    n = MIN_GRANULES * 12
    assert Jackknife.of(np.repeat(np.arange(MIN_GRANULES), 12), np.zeros(n)).groups == MIN_GRANULES
    assert Jackknife.of(np.zeros(9, int), np.arange(9) % 3) is None  # three groups: no sigma to state


def test_nan_replicates_are_left_out():
    jack = Jackknife.of(np.arange(6), np.zeros(6))
    kept = [1.0, 2.0, 3.0, 4.0, 6.0]  # five remain: nu = 4
    assert jack.sigma([1.0, 2.0, np.nan, 3.0, 4.0, 6.0]) == pytest.approx(np.sqrt(4 * np.var(kept) * 4 / 2))
    assert np.isnan(jack.sigma([1.0, np.nan, np.nan, np.nan, np.nan, 2.0]))
