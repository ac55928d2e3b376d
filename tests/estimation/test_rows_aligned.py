"""The FOR's estimate on its FOV rows aligned: rows apart by an EP error do not blur the FOR's turn."""

import numpy as np
import pytest
from scipy.ndimage import shift as scipy_shift

from monitor.core.vocabulary import Cost
from monitor.estimation.estimate import ForSamples, aligned, estimate, rows_apart, shifted

M = 21


def rows_split(apart_steps, n=540, turn=(1.3, -0.7), seed=0):
    """Samples whose scenes match at *turn* (steps; x in-track) for FOVs 4-6, and at turn +-apart/2
    in-track for the rows ahead (7-9) and behind (1-3): VIIRS - CrIS is each scene's gradient times the turn
    from where it matches, plus noise."""
    rng = np.random.default_rng(seed)
    fov = np.tile(np.arange(9), n // 9)
    side = np.where(np.isin(fov, (6, 7, 8)), 0.5, np.where(np.isin(fov, (0, 1, 2)), -0.5, 0.0))
    x, y = np.mgrid[:M, :M] - M // 2
    gx, gy = rng.normal(0, 1, (2, n, 1, 1)) * np.where(side > 0, 3.0, 1.0)[:, None, None]  # sharper ahead
    tx = (turn[0] + side * apart_steps)[:, None, None]
    d = gx * (x[None] - tx) + gy * (y[None] - turn[1]) + 0.05 * rng.normal(size=(n, 1, 1))
    return ForSamples(d, rng.uniform(230, 300, n), np.arange(n) % 6, np.arange(n) % 4, fov=fov)


def test_the_rows_are_found_apart_and_aligned_on_their_common_turn():
    s = rows_split(0.6)
    apart = rows_apart(s, Cost.REGRESSION)
    assert apart[0] == pytest.approx(0.6, abs=0.05) and apart[1] == pytest.approx(0.0, abs=0.05)
    together = aligned(s, apart)
    assert rows_apart(together, Cost.REGRESSION) == pytest.approx((0.0, 0.0), abs=0.05)
    assert aligned(s, (0.0, 0.0)) is s


def test_the_for_offset_is_the_rows_common_turn_and_the_rows_keep_their_difference():
    for apart in (0.0, 0.6, -0.5):
        e = estimate(rows_split(apart), Cost.REGRESSION)
        assert (e.x, e.y) == pytest.approx((1.3, -0.7), abs=0.05)
        assert e.rows == pytest.approx((apart, 0.0), abs=0.05)
        assert np.all(np.isfinite(e.rows_sigma))
    s = rows_split(0.6)
    blurred = estimate(ForSamples(s.d_k, s.cris_k, s.granule, s.scan), Cost.REGRESSION)  # one turn for all
    assert blurred.x - 1.3 > 0.1  # pulled towards the sharper row ahead: what the alignment prevents


@pytest.mark.parametrize("move", [(0.3, -1.7), (-2.5, 0.0), (4.2, 3.9), (25.0, -30.0)])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_surfaces_move_as_scipy_moves_them(move, dtype):
    """A row's move is bilinear on the grid and holds the edge value beyond it: scipy.ndimage's linear
    shift in "nearest" mode, to rounding, in the surfaces' own type (also past the grid's edge)."""
    a = np.random.default_rng(1).normal(size=(5, 4, M, M)).astype(dtype)
    moved = shifted(a, move)
    assert moved.dtype == dtype
    np.testing.assert_allclose(
        moved, scipy_shift(a, (0, 0, *move), order=1, mode="nearest"), atol=4 * np.finfo(dtype).eps
    )
