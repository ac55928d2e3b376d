"""The cost whose minimum over the perturbations is a FOR's offset, and the paper's minimum of a surface.

Equation (8) of Wang et al. (2017): G(i, j, k) = STDEV(BT_VIIRS_ij - BT_CrIS) over the samples of FOR k
(``assessment.cost: stdev``), or its residual after regression on the CrIS BT and its square, which no
CrIS-VIIRS bias, gain or curvature moves (``regression``; docs/science.md, "Cost and minimum"). The grid
minimum is placed between grid points by the quadratic through its 3 x 3 neighbourhood (Wang 2013) where
the exact refinement (:mod:`monitor.estimation.refine`) does not apply.
"""

from __future__ import annotations

import numpy as np

from monitor.core.result import FLAG_EDGE, FLAG_FLAT
from monitor.core.vocabulary import Cost


def _stdev(d: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """STDEV over samples (axis 0 of d, (N, m, m)); with *weights* (B, N) one surface per row (B, m, m)."""
    n, m = d.shape[0], d.shape[1]
    flat = d.reshape(n, -1)
    if weights is None:
        return flat.std(axis=0, ddof=1).reshape(m, m)
    s0 = weights.sum(axis=1, keepdims=True)
    s1 = weights @ flat
    s2 = weights @ (flat * flat)
    var = (s2 - s1 * s1 / s0) / np.maximum(s0 - 1, 1)
    return np.sqrt(np.maximum(var, 0.0)).reshape(-1, m, m)


def calibration_regressors(cris: np.ndarray) -> np.ndarray:
    """The regressors of the regression cost: the CrIS BT and its square about its mean.

    Parameters
    ----------
    cris : numpy.ndarray
        The samples' CrIS BT, K, shape (N,).

    Returns
    -------
    numpy.ndarray
        Shape (N, 2), K and K^2: a CrIS-VIIRS difference bias + gain T + curvature T^2 is explained away.
    """
    c = np.asarray(cris, float) - np.mean(cris)
    return np.stack([c, c * c], axis=1)


def _regression_stdev(d: np.ndarray, cris: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """The residual STDEV of d (N, m, m) regressed on the CrIS BT *cris* (N,) and its square, per
    perturbation: sqrt(Var d - s_dX S_XX^-1 s_Xd). With d = V - C this is the residual of V - f(C) for the
    best quadratic f at each perturbation, so a CrIS-VIIRS calibration difference up to second order
    leaves it unchanged. *weights* (B, N): one surface per replicate (B, m, m)."""
    n, m = d.shape[0], d.shape[1]
    x = calibration_regressors(cris)
    flat = np.concatenate([d.reshape(n, -1), x], axis=1)
    w = np.ones((1, n)) if weights is None else np.asarray(weights, float)
    s0 = w.sum(axis=1)[:, None]
    mean = (w @ flat) / s0
    res = np.empty((len(w), m * m))
    for b in range(len(w)):  # one replicate at a time: (N, K) products stay small
        c = flat - mean[b]
        wc = c * w[b][:, None]
        var_d = np.einsum("nk,nk->k", wc[:, :-2], c[:, :-2])
        s_dx = wc[:, :-2].T @ c[:, -2:]  # (K, 2)
        s_xx = wc[:, -2:].T @ c[:, -2:]  # (2, 2)
        explained = np.einsum("ka,ab,kb->k", s_dx, np.linalg.inv(s_xx), s_dx)
        res[b] = (var_d - explained) / max(s0[b, 0] - 1, 1)
    g = np.sqrt(np.maximum(res, 0.0)).reshape(-1, m, m)
    return g[0] if weights is None else g


def cost_surface(
    d: np.ndarray, cris: np.ndarray, cost: Cost, weights: np.ndarray | None = None
) -> np.ndarray:
    """The cost over the perturbation grid of one FOR's samples (:class:`~monitor.core.vocabulary.Cost`).

    Parameters
    ----------
    d : numpy.ndarray
        Each sample's VIIRS minus CrIS BT at every perturbation, K, shape (N, m, m).
    cris : numpy.ndarray
        The samples' CrIS BT, K, shape (N,).
    cost : Cost
        The cost (``assessment.cost``).
    weights : numpy.ndarray, optional
        Replicate weights of the samples, shape (B, N): one surface per replicate.

    Returns
    -------
    numpy.ndarray
        The cost, K, shape (m, m) or (B, m, m).
    """
    return _stdev(d, weights) if cost == Cost.STDEV else _regression_stdev(d, cris, weights)


# The quadratic a + b x + c y + d x^2 + e x y + f y^2 fitted by least squares to a 3 x 3 neighbourhood
# (steps -1, 0, 1): its coefficients are this matrix times the nine values, row by row
_X, _Y = (g.ravel() for g in np.meshgrid([-1.0, 0.0, 1.0], [-1.0, 0.0, 1.0], indexing="ij"))
_QUADRATIC_FIT = np.linalg.pinv(np.stack([np.ones(9), _X, _Y, _X**2, _X * _Y, _Y**2], 1))


def _vertex(cost: np.ndarray, i0: int, j0: int) -> tuple[float, float, float] | None:
    """The vertex (steps from (i0, j0), each within +-1) and value of the quadratic fitted to the 3 x 3
    about an interior grid point; None where the fit is not convex."""
    c = _QUADRATIC_FIT @ cost[i0 - 1 : i0 + 2, j0 - 1 : j0 + 2].ravel()
    hess = np.array([[2 * c[3], c[4]], [c[4], 2 * c[5]]])
    if np.linalg.det(hess) <= 0 or hess[0, 0] <= 0:
        return None
    dx, dy = (float(v) for v in np.clip(np.linalg.solve(hess, -c[1:3]), -1, 1))
    return dx, dy, float(c[0] + c[1] * dx + c[2] * dy + c[3] * dx * dx + c[4] * dx * dy + c[5] * dy * dy)


def find_minimum(cost: np.ndarray, contrast: float = 0.03) -> tuple[float, float, list[str]]:
    """The sub-step minimum of a cost surface by the quadratic through the 3 x 3 about the grid minimum (Wang
    2013).

    Parameters
    ----------
    cost : numpy.ndarray
        The cost surface, K, shape (m, m).
    contrast : float
        The relative rise from the minimum to the grid's border below which a surface is flagged ``flat``.

    Returns
    -------
    x, y : float
        The minimum, grid steps from the centre (in-track, cross-track).
    flags : list of str
        ``edge`` where the grid minimum is on the border (not refined); ``flat`` where the surface rises less
        than *contrast* or its fit is not convex.
    """
    m = cost.shape[0]
    n = (m - 1) // 2
    flags = []
    if not np.all(np.isfinite(cost)):
        return np.nan, np.nan, [FLAG_FLAT]
    i0, j0 = np.unravel_index(np.argmin(cost), cost.shape)
    border = np.concatenate([cost[0], cost[-1], cost[1:-1, 0], cost[1:-1, -1]])
    if (np.mean(border) - cost[i0, j0]) / cost[i0, j0] < contrast:
        flags.append(FLAG_FLAT)
    if i0 in (0, m - 1) or j0 in (0, m - 1):
        return float(i0 - n), float(j0 - n), flags + [FLAG_EDGE]
    vertex = _vertex(cost, int(i0), int(j0))
    if vertex is None:
        return float(i0 - n), float(j0 - n), sorted(set(flags + [FLAG_FLAT]))
    return i0 - n + vertex[0], j0 - n + vertex[1], flags


def minimum_value(cost: np.ndarray) -> float:
    """The cost at the sub-step minimum of :func:`find_minimum`: the fitted quadratic's value at its vertex.

    The grid minimum is the value at the grid point nearest the minimum, so as the minimum moves between
    points it rises and falls by up to the surface's curvature over half a step; this value does not. The
    day's lift is searched on a sum of such minima (:mod:`monitor.estimation.parallax`).

    Parameters
    ----------
    cost : numpy.ndarray
        The cost surface, K, shape (m, m); NaN where a perturbation has no value.

    Returns
    -------
    float
        K; the grid minimum where it lies on the border, the fit is not convex or the surface has NaN.
    """
    m = cost.shape[0]
    if not np.all(np.isfinite(cost)):
        return float(np.nanmin(cost))
    i0, j0 = np.unravel_index(np.argmin(cost), cost.shape)
    vertex = None if i0 in (0, m - 1) or j0 in (0, m - 1) else _vertex(cost, int(i0), int(j0))
    return float(cost[i0, j0]) if vertex is None else vertex[2]
