"""Cone sums smoothed over the perturbations: a pixel's in-or-out spread over its neighbours, nothing made or
lost, a smooth surface kept."""

import numpy as np

from monitor.collocation.sums import ConeSums, smoothed


def _cones(sums, weights, rendered=None):
    return ConeSums((0.01,), sums, weights, np.array([1.0]), rendered)


def test_a_step_in_one_perturbation_spreads_over_its_neighbours():
    m = 5
    sums = np.zeros((1, 1, m, m))
    sums[0, 0, 2, 2] = 16.0
    out = smoothed(_cones(sums, np.ones_like(sums))).sums[0, 0]
    expected = 16.0 * np.outer([0, 0.25, 0.5, 0.25, 0], [0, 0.25, 0.5, 0.25, 0])
    assert np.allclose(out, expected)
    assert out.sum() == 16.0


def test_a_surface_linear_in_the_perturbation_is_kept_inside_the_grid():
    m = 7
    i, j = np.mgrid[0:m, 0:m].astype(float)
    sums = (3.0 + 0.5 * i - 0.25 * j)[None, None]
    weights = np.full_like(sums, 2.0)
    out = smoothed(_cones(sums, weights))
    assert np.allclose(out.sums[0, 0, 1:-1, 1:-1], sums[0, 0, 1:-1, 1:-1])
    assert np.allclose(out.weights, 2.0)  # a constant everywhere, the edges too
    # at the edge the missing neighbour is the edge itself: a quarter step inwards
    assert np.allclose(out.sums[0, 0, 0, 3], sums[0, 0, 0, 3] + 0.25 * 0.5)


def test_the_rendered_views_are_smoothed_alike():
    rng = np.random.default_rng(1)
    sums = rng.normal(size=(2, 3, 5, 5))
    weights = rng.uniform(1, 2, size=sums.shape)
    cones = _cones(sums, weights, rendered=_cones(sums.copy(), weights.copy()))
    out = smoothed(cones)
    assert out.rendered is not None
    assert np.array_equal(out.rendered.sums, out.sums)
    assert np.array_equal(out.rendered.weights, out.weights)
    assert not np.allclose(out.sums, sums)
