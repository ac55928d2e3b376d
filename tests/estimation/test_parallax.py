"""The day's parallax scale from its own cost: the blend of two collocations, the search, its significance
and its sigma."""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from monitor.core.vocabulary import Cost
from monitor.estimation.estimate import ForSamples
from monitor.estimation.parallax import (
    GAIN_SIGMAS,
    MIN_LIFT_M_PER_K,
    ROWS,
    blend,
    day_cost,
    day_fraction,
    day_lift,
    keeps,
    row_costs,
    sensitivity,
)

PROBE_M_PER_K = 180.0  # the fraction's unit in these tests

M = 21


def pair(true_f, depth, n=180, granules=6, seed=0):
    """Two collocations of one FOR (at no lift and at the probe's) whose samples agree best at *true_f*
    of the probe: each sample's VIIRS-CrIS difference is a bowl about the centre plus a pattern of its own
    scaled by (f - true_f), and noise. The pattern is smooth over the grid, as a real one is: neighbouring
    perturbed cones share most of their pixels."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:M, :M] - M // 2
    bowl = 0.02 * (x**2 + y**2)
    pattern = gaussian_filter(rng.normal(size=(n, M, M)), (0, 2.0, 2.0))
    pattern *= depth / pattern.std()
    base = bowl * rng.uniform(0.5, 1.5, (n, 1, 1)) + rng.normal(0, 0.05, (n, 1, 1))
    cris = rng.uniform(230, 300, n)
    granule = np.repeat(np.arange(granules), n // granules)
    fov = np.tile(np.arange(9), n // 9 + 1)[:n]
    make = lambda f: ForSamples(base + (f - true_f) * pattern, cris, granule, np.zeros(n, int), fov=fov)  # noqa: E731
    return make(0.0), make(1.0)


def test_blend_is_the_collocation_at_the_fraction():
    s0, s1 = pair(0.6, 0.5)
    assert np.array_equal(blend(s0, s1, 0.0).d_k, s0.d_k) and np.allclose(blend(s0, s1, 1.0).d_k, s1.d_k)
    assert np.allclose(blend(s0, s1, 0.25).d_k, 0.75 * s0.d_k + 0.25 * s1.d_k)


@pytest.mark.parametrize("true_f", [0.6, 1.1, 1.7])
def test_the_search_finds_the_fraction_the_samples_agree_at(true_f):
    fors = [pair(true_f, 0.5, seed=k) for k in range(6)]
    s0, s1 = [a for a, _ in fors], [b for _, b in fors]
    for cost in Cost:
        assert day_fraction(s0, s1, cost) == pytest.approx(true_f, abs=0.05)
    f, sigma = day_lift(s0, s1, Cost.STDEV, PROBE_M_PER_K)
    assert f == pytest.approx(true_f, abs=0.05) and 0 < sigma < 0.1


def test_a_replicate_searched_about_another_fraction_stays_within_its_bracket():
    """A replicate's search about *near* keeps the parabola's vertex between the outer two of its three
    points, though the samples agree best far outside them."""
    fors = [pair(1.8, 0.5, seed=k) for k in range(6)]
    s0, s1 = [a for a, _ in fors], [b for _, b in fors]
    step = 0.25
    found = day_fraction(s0, s1, Cost.STDEV, near=0.5)
    assert found == pytest.approx(0.5 + step)
    assert day_fraction(s0, s1, Cost.STDEV, near=1.75) == pytest.approx(1.8, abs=0.05)  # bracketed


def test_a_lift_that_gains_nothing_significant_is_declined_and_its_size_is_the_sigma():
    fors = [pair(0.6, 0.01, seed=k) for k in range(6)]  # a shallow preference for a cloud's lift
    s0, s1 = [a for a, _ in fors], [b for _, b in fors]
    found = day_fraction(s0, s1, Cost.STDEV)
    f, sigma = day_lift(s0, s1, Cost.STDEV, PROBE_M_PER_K)
    assert found * PROBE_M_PER_K > MIN_LIFT_M_PER_K and f == 0.0 and sigma >= found
    few = [ForSamples(a.d_k, a.cris_k, a.granule % 2, a.scan, fov=a.fov) for a in s0]  # 2 granules: no sigma
    assert np.isnan(
        day_lift(
            few,
            [ForSamples(b.d_k, b.cris_k, b.granule % 2, b.scan, fov=b.fov) for b in s1],
            Cost.STDEV,
            PROBE_M_PER_K,
        )[1]
    )


def test_a_lift_smaller_than_any_clouds_is_declined_however_much_it_gains():
    fors = [pair(0.15, 0.5, seed=k) for k in range(6)]  # a sharp preference for 27 m/K
    s0, s1 = [a for a, _ in fors], [b for _, b in fors]
    found = day_fraction(s0, s1, Cost.STDEV)
    assert found == pytest.approx(0.15, abs=0.05)
    assert day_lift(s0, s1, Cost.STDEV, PROBE_M_PER_K)[0] == 0.0
    assert day_lift(s0, s1, Cost.STDEV, 2 * MIN_LIFT_M_PER_K / found)[0] == pytest.approx(found)


@pytest.mark.parametrize(
    ("lift_m_per_k", "gain_sigmas", "kept"),
    [(120.0, 1.5, True), (120.0, 0.9, False), (40.0, 9.0, False), (MIN_LIFT_M_PER_K, 1.01, True)],
)
def test_the_rule_asks_a_clouds_size_and_a_gain_beyond_its_sigma(lift_m_per_k, gain_sigmas, kept):
    """*gain_sigmas* in units of the rule's own GAIN_SIGMAS."""
    assert keeps(lift_m_per_k, gain_sigmas * GAIN_SIGMAS * 0.2, 0.2) is kept


def test_the_day_cost_is_its_rows_costs_summed():
    fors = [pair(0.8, 0.5, seed=k) for k in range(3)]
    s0, s1 = [a for a, _ in fors], [b for _, b in fors]
    rows = row_costs(s0, s1, 0.3, Cost.STDEV)
    assert rows.shape == (len(ROWS),) and rows.sum() == pytest.approx(day_cost(s0, s1, 0.3, Cost.STDEV))
    for a, b in fors:  # the lift no longer changes the rows behind: only their cost moves
        behind = np.isin(a.fov, ROWS[2])
        b.d_k[behind] = a.d_k[behind]
    moved = row_costs(s0, s1, 0.3, Cost.STDEV)
    assert np.allclose(moved[:2], rows[:2]) and moved[2] != pytest.approx(rows[2])


def test_the_sensitivity_is_how_far_the_minimum_moves_per_unit_fraction():
    n, y, x = 90, *np.mgrid[:M, :M]
    rng = np.random.default_rng(1)
    cris = rng.uniform(230, 300, n)
    fov = np.tile(np.arange(9), 10)
    # the rows ahead's bowl moves +2 steps in alpha per unit f, the rows behind's -2, the middle stays
    shift = np.where(np.isin(fov, (6, 7, 8)), 2.0, np.where(np.isin(fov, (0, 1, 2)), -2.0, 0.0))
    bowls = [
        0.05
        * ((x[None] - 10 - f * shift[:, None, None]) ** 2 + (y[None] - 10) ** 2)
        * rng.uniform(0.5, 1.5, (n, 1, 1))
        for f in (0.0, 1.0)
    ]
    s0, s1 = (ForSamples(b, cris, np.zeros(n, int), np.zeros(n, int), fov=fov) for b in bowls)
    d = sensitivity(s0, s1, 0.5, Cost.STDEV)  # steps per unit f: FOR alpha, beta; rows alpha, beta
    rows = sorted(np.abs(d[2:]))
    assert rows[0] < 0.3 and rows[1] == pytest.approx(4.0, abs=0.4)  # ahead minus behind: 2 - (-2)
    assert np.all(np.abs(d[:2]) < 0.5)  # the FOR's own minimum hardly moves


def test_an_error_of_the_rows_does_not_pull_the_lift():
    """Rows ahead and behind turned 2 steps apart (an EP error, the same for every scene), and a parallax
    that turns them apart by 1.5 steps times each scene's coldness (0..1) unless the lift undoes it: the
    lift the samples agree at is the parallax's, whatever the rows' error."""
    n, y, x = 540, *np.mgrid[:M, :M]
    rng = np.random.default_rng(2)
    fov = np.tile(np.arange(9), n // 9)
    side = np.where(np.isin(fov, (6, 7, 8)), 1.0, np.where(np.isin(fov, (0, 1, 2)), -1.0, 0.0))
    cold = rng.uniform(0, 1, n)
    gx, gy, noise = rng.normal(0, 1, (3, n, 1, 1))

    def collocated(f, true_f=0.8):
        """VIIRS - CrIS of each sample: its scene's gradient (K per step) times the turn from where it
        matches, its row's turn and what of the parallax the lift leaves, linear in f."""
        turn = (side * (1.0 + 1.5 * (true_f - f) * cold))[:, None, None]
        return gx * (x[None] - 10 - turn) + gy * (y[None] - 10) + 0.05 * noise

    s0, s1 = (
        ForSamples(collocated(f), rng.uniform(230, 300, n), np.arange(n) % 6, np.zeros(n, int), fov=fov)
        for f in (0.0, 1.0)
    )
    assert day_fraction([s0], [s1], Cost.STDEV) == pytest.approx(0.8, abs=0.05)
    whole = [ForSamples(s.d_k, s.cris_k, s.granule, s.scan) for s in (s0, s1)]  # no FOVs: one turn per FOR
    assert abs(day_fraction([whole[0]], [whole[1]], Cost.STDEV) - 0.8) > 0.2  # what the rows' turns prevent
