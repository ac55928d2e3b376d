"""The regression cost: a CrIS gain and bias leave it and the offsets unchanged, the refinement is exact for
it, and the intercalibration at its optimum recovers them."""

import numpy as np
import pytest

from monitor.core.constants import DEFAULT_STEP_URAD
from monitor.core.vocabulary import Cost
from monitor.estimation import refine
from monitor.estimation.cost import calibration_regressors, cost_surface, find_minimum, minimum_value
from monitor.estimation.estimate import ForSamples, estimate


def _samples(rng, n=300, m=21):
    """d = V - C on a grid: V_ij a smooth shift of a textured truth T, C = T + noise."""
    t = rng.normal(280.0, 8.0, n)
    grad = rng.normal(0.0, 3.0, n)
    ii, jj = np.meshgrid(np.arange(m) - 10.0, np.arange(m) - 10.0, indexing="ij")
    v = t[:, None, None] + grad[:, None, None] * (0.3 * (ii - 1.2) ** 2 + 0.2 * (jj + 2.1) ** 2) ** 0.5 / 10
    v += rng.normal(0.0, 0.2, v.shape)
    return v, t + rng.normal(0.0, 0.1, n)


def test_a_calibration_difference_on_cris_leaves_the_regression_cost_as_it_was():
    """A gain and a bias exactly (the regressors span the same functions); with a curvature too, to the
    second order of a 0.5 K term over the scene's range."""
    rng = np.random.default_rng(1)
    v, c = _samples(rng)
    before = cost_surface(v - c[:, None, None], c, Cost.REGRESSION)
    x = c - 280.0
    linear = c + 1.5 + 0.03 * x
    assert np.allclose(cost_surface(v - linear[:, None, None], linear, Cost.REGRESSION), before, rtol=1e-9)
    curved = linear + 0.5 * (x / 30.0) ** 2  # the simulator's law (simulate/case.py)
    after = cost_surface(v - curved[:, None, None], curved, Cost.REGRESSION)
    assert np.allclose(after, before, rtol=1e-3)
    assert np.unravel_index(np.argmin(after), after.shape) == np.unravel_index(
        np.argmin(before), before.shape
    )
    stdev = cost_surface(v - linear[:, None, None], linear, Cost.STDEV)  # the paper's cost does change
    assert not np.allclose(stdev, cost_surface(v - c[:, None, None], c, Cost.STDEV), rtol=1e-3)


def test_the_refinement_is_exact_for_the_regression_cost():
    """On the grid nodes the refinement's quadratic form w^T S' w equals the regression cost squared, and
    the bootstrap replicates' surfaces agree with the same counts."""
    rng = np.random.default_rng(2)
    v, c = _samples(rng)
    d = v - c[:, None, None]
    g = cost_surface(d, c, Cost.REGRESSION)
    s = refine.window_covariance(d, 10, 10, cris=calibration_regressors(c))
    for dx, dy in [(0, 0), (1, -1), (-1, 1)]:
        w = np.outer(_node(dx), _node(dy)).ravel()
        assert w @ s @ w == pytest.approx(g[10 + dx, 10 + dy] ** 2, rel=1e-9)
    counts = rng.poisson(1.0, (3, len(d))).astype(float)
    stacked = refine.window_covariance(d, 10, 10, counts, calibration_regressors(c))
    replicas = cost_surface(d, c, Cost.REGRESSION, counts)
    w = np.outer(_node(0), _node(0)).ravel()
    assert np.allclose([w @ sb @ w for sb in stacked], replicas[:, 10, 10] ** 2, rtol=1e-9)


def _node(k):
    """The interpolation weights at a window node: 1 there, 0 elsewhere."""
    w = np.zeros(2 * refine.HALF + 1)
    w[refine.HALF + k] = 1.0
    return w


def _minimum(d, c):
    scan = np.arange(len(c)) // 3  # three samples a scan, ten scans a granule
    return estimate(ForSamples(d, c, scan // 10, scan % 10), Cost.REGRESSION)


def test_a_calibration_difference_leaves_the_offsets_and_sigmas_and_is_recovered_at_the_optimum():
    """Offsets and their jackknife sigmas within 1 urad of the agreeing instruments'; the bias and gain
    fitted at the optimum are the injected ones (the truth's V at the optimum is T + noise): 2000 samples,
    so that the scenes determine a gain to intercal.GAIN_RESOLUTION_PCT (300 do not: it is then left out)."""
    rng = np.random.default_rng(5)
    v, c = _samples(rng, n=2000)
    agree = _minimum(v - c[:, None, None], c)
    assert agree.refined
    law = c + 1.5 + 0.03 * (c - 280.0)  # a 3 % gain and a 1.5 K bias on every CrIS BT
    differ = _minimum(v - law[:, None, None], law)
    step = DEFAULT_STEP_URAD
    assert abs(differ.x - agree.x) * step < 1.0 and abs(differ.y - agree.y) * step < 1.0
    assert np.allclose(np.array(differ.sigma) * step, np.array(agree.sigma) * step, atol=1.0)
    # the optimum's VIIRS BT: interpolated with the refinement's weights, d + C
    viirs = differ.d_opt + law
    assert np.allclose(viirs, agree.d_opt + c)
    cal = differ.intercalibration
    assert cal.bias_k == pytest.approx(1.5, abs=0.05) and cal.gain_pct == pytest.approx(3.0, abs=0.2)
    assert 0 < cal.sigma_bias_k < 0.05 and 0 < cal.sigma_gain_pct < 0.1


def _bowl(centre, m=21):
    """A quadratic cost surface, K, least (1.0 K) at *centre* (steps from the grid's centre, in-track and
    cross-track), its axes turned from the grid's."""
    x, y = (np.mgrid[:m, :m] - m // 2).astype(float)
    dx, dy = x - centre[0], y - centre[1]
    return 1.0 + 0.05 * dx**2 + 0.02 * dx * dy + 0.03 * dy**2


@pytest.mark.parametrize("centre", [(0.0, 0.0), (0.49, -0.3), (0.51, 0.2), (-3.7, 6.45)])
def test_the_minimum_value_is_the_surfaces_least_between_grid_points(centre):
    surface = _bowl(centre)
    x, y, flags = find_minimum(surface)
    assert (x, y) == pytest.approx(centre, abs=1e-9) and not flags
    assert minimum_value(surface) == pytest.approx(1.0, abs=1e-12)
    assert minimum_value(surface) < surface.min() or centre == (0.0, 0.0)


def test_the_minimum_value_does_not_rise_and_fall_as_the_minimum_moves_between_grid_points():
    centres = np.linspace(-1.0, 1.0, 41)
    values = [minimum_value(_bowl((c, 0.3 * c))) for c in centres]
    grid = [float(_bowl((c, 0.3 * c)).min()) for c in centres]
    assert np.ptp(values) < 1e-9 and np.ptp(grid) > 0.01


def test_the_minimum_value_is_the_grid_minimum_on_the_border_or_with_gaps():
    surface = _bowl((12.0, 0.0))  # beyond the grid: its minimum on the border
    assert minimum_value(surface) == surface.min()
    gapped = _bowl((0.3, 0.0))
    gapped[5, 5] = np.nan
    assert minimum_value(gapped) == np.nanmin(gapped)
