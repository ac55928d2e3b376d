"""The delete-one-granule jackknife: the standard error of a mean exactly, granules as groups from three,
scans below."""

import numpy as np
import pytest

from monitor.jackknife import MIN_GRANULES, Jackknife


def test_the_jackknife_of_a_mean_is_its_standard_error():
    rng = np.random.default_rng(1)
    granule = np.repeat(np.arange(6), 20)
    x = rng.normal(0.0, 1.0, 6)[granule] + rng.normal(0.0, 0.1, granule.size)
    jack = Jackknife.of(granule, np.zeros(granule.size))
    assert jack.groups == 6
    replicates = jack.counts @ x / jack.counts.sum(axis=1)
    means = np.bincount(granule, x) / 20
    assert jack.sigma(replicates) == pytest.approx(means.std(ddof=1) / np.sqrt(6), rel=1e-12)


def test_the_groups_are_granules_from_three_else_scans():
    scan = np.tile(np.repeat(np.arange(4), 9), 2)
    two = Jackknife.of(np.repeat([0, 1], 36), scan)
    assert two.groups == 8  # two granules of four scans: the scans
    assert Jackknife.of(np.repeat(np.arange(MIN_GRANULES), 12), np.zeros(36)).groups == MIN_GRANULES
    assert Jackknife.of(np.zeros(9, int), np.zeros(9, int)) is None  # one group: no spread to measure


def test_nan_replicates_are_left_out():
    jack = Jackknife.of(np.arange(5), np.zeros(5))
    assert jack.sigma([1.0, 2.0, np.nan, 3.0, 4.0]) == pytest.approx(np.sqrt(3 * np.var([1, 2, 3, 4])))
