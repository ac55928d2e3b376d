"""Sub-step minimum of the cost G = STDEV(BT_VIIRS - BT_CrIS) (or its regression form) between the
perturbation grid points.

A quadratic surface through the 3 x 3 neighbourhood of the grid minimum (Wang 2013) places the minimum
to no better than ~15-30 urad on a 450 urad grid: near its minimum G is closer to a cone than to a
paraboloid (it is the square root of a variance), and the fit is biased towards the grid point.

Here the model is put where it is smooth: in the samples. For each sample (FOV) n the VIIRS cone mean, and
so the difference d_n(i, j) = BT_VIIRS - BT_CrIS, varies smoothly with the perturbation: a shift of one
step (~one I5 pixel) changes a thin crescent of a cone sixty pixels wide. Each d_n is interpolated between
grid points by cubic convolution (Keys 1981, a = -1/2; exact for quadratics), with weights w(x, y) over a
7 x 7 window around the grid minimum, so that

    d_n(x, y) = sum_k w_k(x, y) d_n,k      and      G^2(x, y) = w(x, y)^T S w(x, y),

where S (49 x 49) is the covariance over samples of the window's values. G^2 is then evaluated exactly on
ever finer grids (1/4, 1/16, 1/64, 1/256 and 1/1024 of a step, within +-1.5 steps of the grid minimum; the
last, 0.44 urad, below what the footprint fit of :mod:`monitor.estimation.estimate` tells apart). No further
collocation is needed, and the same S, weighted by bootstrap counts, gives the bootstrap replicates.
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike

HALF = 3  # window half-width (grid steps): the search range +-1.5 needs cubic support +-3
REACH = 1.5  # how far (grid steps) from the grid minimum the refined minimum may lie
ZOOMS = (0.25, 1.0 / 16.0, 1.0 / 64.0, 1.0 / 256.0, 1.0 / 1024.0)


def keys_weights(x: ArrayLike) -> np.ndarray:
    """Cubic convolution weights on the window's nodes -HALF..HALF for sub-step positions.

    Parameters
    ----------
    x : array_like
        Positions, grid steps from the window centre, |x| <= REACH.

    Returns
    -------
    numpy.ndarray
        Weights, shape ``x.shape + (2 * HALF + 1,)``.
    """
    x = np.asarray(x, float)
    base = np.floor(x)
    t = x - base
    taps = np.stack(
        [
            ((-0.5 * t + 1.0) * t - 0.5) * t,
            (1.5 * t - 2.5) * t * t + 1.0,
            ((-1.5 * t + 2.0) * t + 0.5) * t,
            (0.5 * t - 0.5) * t * t,
        ],
        -1,
    )
    w = np.zeros(x.shape + (2 * HALF + 1,))
    first = (base - 1 + HALF).astype(int)
    np.put_along_axis(w, first[..., None] + np.arange(4), taps, axis=-1)  # the four taps at once
    return w


def _path(subscripts: str, *operands: np.ndarray) -> list:
    """The contraction order numpy's greedy search chooses for *operands* of these shapes, found once per
    shapes (the search costs more than the contraction of these small arrays)."""
    return _path_of_shapes(subscripts, tuple(o.shape for o in operands))


@functools.lru_cache(maxsize=256)
def _path_of_shapes(subscripts: str, shapes: tuple) -> list:
    return np.einsum_path(subscripts, *(np.empty(s) for s in shapes), optimize="greedy")[0]


def refinable(i0: int, j0: int, m: int) -> bool:
    """Whether the window around a grid minimum lies inside the grid.

    Parameters
    ----------
    i0, j0 : int
        The grid minimum, the window's centre (in-track, cross-track indices).
    m : int
        The grid's size, 2n + 1.

    Returns
    -------
    bool
        True when the 7 x 7 window fits.
    """
    return HALF <= i0 < m - HALF and HALF <= j0 < m - HALF


def window_covariance(
    d: np.ndarray, i0: int, j0: int, counts: np.ndarray | None = None, cris: np.ndarray | None = None
) -> np.ndarray:
    """The covariance over samples of the BT differences in the window around a grid minimum.

    With *cris*, the covariance of what of d the regressors do not explain: the residual of d_interp = w^T d
    regressed on X has variance w^T (S_dd - S_dX S_XX^-1 S_Xd) w, a quadratic form in the same weights with
    the Schur complement of S_XX returned here, as long as the regressors are fixed (they are the samples'
    own).

    Parameters
    ----------
    d : numpy.ndarray
        Each sample's VIIRS minus CrIS BT at every perturbation, K, shape (N, m, m).
    i0, j0 : int
        The grid minimum, the window's centre (in-track, cross-track indices).
    counts : numpy.ndarray, optional
        Replicate weights of the samples, shape (B, N): one covariance per replicate.
    cris : numpy.ndarray, optional
        The regression cost's regressors, shape (N, R) (the CrIS BT and its square,
        :func:`monitor.estimation.cost.calibration_regressors`).

    Returns
    -------
    numpy.ndarray
        K^2, shape (49, 49), or (B, 49, 49) with *counts*.
    """
    x = d[:, i0 - HALF : i0 + HALF + 1, j0 - HALF : j0 + HALF + 1].reshape(len(d), -1)
    if cris is None:
        return _covariance(x, counts)
    nx = x.shape[1]
    joint = _covariance(np.concatenate([x, np.asarray(cris, float)], axis=1), counts)
    s_dx = joint[..., :nx, nx:]
    return joint[..., :nx, :nx] - s_dx @ np.linalg.inv(joint[..., nx:, nx:]) @ np.swapaxes(s_dx, -1, -2)


def window_values(d: np.ndarray, i0: int, j0: int, x: ArrayLike, y: ArrayLike) -> np.ndarray:
    """The samples' BT differences interpolated at sub-step positions, with the weights of the minimum.

    Parameters
    ----------
    d : numpy.ndarray
        Each sample's VIIRS minus CrIS BT at every perturbation, K, shape (N, m, m).
    i0, j0 : int
        The grid minimum, the window's centre (in-track, cross-track indices).
    x, y : array_like
        Positions, grid steps from the window centre (scalars, or (B,) for one row per position).

    Returns
    -------
    numpy.ndarray
        d_n(x, y) = w(x, y)^T d_n, K, shape (N,) or (B, N).
    """
    win = d[:, i0 - HALF : i0 + HALF + 1, j0 - HALF : j0 + HALF + 1]
    return np.einsum("nab,...a,...b->...n", win, keys_weights(x), keys_weights(y))


def _covariance(x: np.ndarray, counts: np.ndarray | None = None) -> np.ndarray:
    """Covariance over samples (rows) of *x* (N, K); with *counts* (B, N) one per replicate (B, K, K)."""
    x = x - x.mean(axis=0)  # centred once: the covariance does not depend on it, rounding does
    if counts is None:
        return np.cov(x, rowvar=False)
    counts = np.asarray(counts, float)
    s0 = counts.sum(axis=1)
    s1 = counts @ x
    outer = (x[:, :, None] * x[:, None, :]).reshape(len(x), -1)
    s2 = (counts @ outer).reshape(len(counts), x.shape[1], x.shape[1])
    return (s2 - s1[:, :, None] * s1[:, None, :] / s0[:, None, None]) / np.maximum(s0 - 1, 1)[:, None, None]


def refined_minimum(cov: np.ndarray) -> np.ndarray:
    """The sub-step position where the quadratic form w^T S w is least.

    The weights are separable, w = wx (x) wy, so on a grid of positions the form is contracted over the x
    nodes first and then over the y nodes; searched down to 1/1024 of a step.

    Parameters
    ----------
    cov : numpy.ndarray
        One window covariance (49, 49) or a stack (B, 49, 49), K^2.

    Returns
    -------
    numpy.ndarray
        (x, y) grid steps from the window centre, |x|, |y| <= REACH, shape (2,) or (B, 2).
    """
    s = np.asarray(cov, float)
    single = s.ndim == 2
    nw = 2 * HALF + 1
    s = s.reshape(-1, nw, nw, nw, nw)  # (B, x node, y node, x node, y node)
    nb = len(s)
    centre = np.zeros((nb, 2))
    span = REACH
    for step in ZOOMS:
        offs = np.arange(-span, span + step / 2, step)
        xs = np.clip(centre[:, :1] + offs, -REACH, REACH)  # (B, P)
        ys = np.clip(centre[:, 1:] + offs, -REACH, REACH)
        wx, wy = keys_weights(xs), keys_weights(ys)  # (B, P, 7)
        t = np.einsum("bpa,bajcl,bpc->bpjl", wx, s, wx, optimize=_path("bpa,bajcl,bpc->bpjl", wx, s, wx))
        var = np.einsum("bqj,bpjl,bql->bpq", wy, t, wy, optimize=_path("bqj,bpjl,bql->bpq", wy, t, wy))
        best = np.argmin(var.reshape(nb, -1), axis=1)
        p, q = np.divmod(best, len(offs))
        centre = np.stack([xs[np.arange(nb), p], ys[np.arange(nb), q]], -1)
        span = 2 * step
    return centre[0] if single else centre
