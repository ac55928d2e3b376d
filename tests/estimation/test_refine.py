"""The sub-step minimum by cubic convolution of the samples (monitor/estimation/refine.py)."""

import numpy as np
import pytest

from monitor.estimation import refine


def test_keys_weights_sum_to_one_and_reproduce_quadratics():
    x = np.linspace(-refine.REACH, refine.REACH, 37)
    w = refine.keys_weights(x)
    nodes = np.arange(-refine.HALF, refine.HALF + 1)
    assert np.allclose(w.sum(-1), 1.0)
    for poly in (nodes, nodes**2 - 3 * nodes):
        assert np.allclose(w @ poly, np.interp(x, nodes, poly) if poly is nodes else x**2 - 3 * x)


def _samples(x0, y0, n=400, m=21, seed=0):
    """Differences d_n(i, j) = c_n + e_n (i - x0) + f_n (j - y0) with orthogonal c, e, f: the variance over
    samples is var(c) + var(e) (i - x0)^2 + var(f) (j - y0)^2, least at (x0, y0)."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(np.column_stack([np.ones(n), rng.standard_normal((n, 3))]))  # zero-mean columns 1-3
    c, e, f = q[:, 1] * 3, q[:, 2] * 2, q[:, 3] * 1.5
    i = np.arange(m) - m // 2
    return c[:, None, None] + e[:, None, None] * (i[:, None] - x0) + f[:, None, None] * (i[None, :] - y0)


@pytest.mark.parametrize("x0,y0", [(0.0, 0.0), (0.37, -0.81), (-3.4, 2.62), (4.49, -4.2)])
def test_refined_minimum_finds_the_variance_minimum(x0, y0):
    d = _samples(x0, y0)
    m = d.shape[1]
    cost = d.std(axis=0)
    i0, j0 = np.unravel_index(np.argmin(cost), cost.shape)
    assert refine.refinable(i0, j0, m)
    dx, dy = refine.refined_minimum(refine.window_covariance(d, i0, j0))
    assert i0 - m // 2 + dx == pytest.approx(x0, abs=1 / 256) and j0 - m // 2 + dy == pytest.approx(
        y0, abs=1 / 256
    )


def test_bootstrap_covariances_match_one_by_one():
    d = _samples(0.3, -0.2, n=60)
    counts = np.random.default_rng(1).multinomial(60, np.full(60, 1 / 60), size=3)
    stacked = refine.window_covariance(d, 10, 10, counts)
    for b in range(3):
        rep = np.repeat(d, counts[b], axis=0)
        assert np.allclose(stacked[b], refine.window_covariance(rep, 10, 10))
    assert refine.refined_minimum(stacked).shape == (3, 2)


def test_window_must_fit():
    assert (
        not refine.refinable(2, 10, 21) and not refine.refinable(10, 18, 21) and refine.refinable(3, 17, 21)
    )
