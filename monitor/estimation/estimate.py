"""The estimator of Wang et al. 2017 (section 2.4): one FOR's day of samples in, its offsets, their
uncertainty and the intercalibration out.

Its input, :class:`ForSamples`, is what collocation leaves per FOR (:mod:`monitor.assessment.assess` from
granules, :mod:`monitor.assessment.replay` from the reference implementation's files): for every sample (a FOV
of a scan of a
granule) the VIIRS-minus-CrIS BT at every perturbation through the top-hat cone, the CrIS BT, and where the
collocation measured them, the VIIRS radiance means over annuli about each perturbed LOS.

The cost (equation 8, or its regression form; :func:`cost_surface`) has its minimum refined between grid
points by :mod:`monitor.estimation.refine`. Then:

**The footprint.** CrIS sees the scene through a smooth, radially symmetric response that reaches past the
0.963 deg cone (:mod:`monitor.instrument.footprint`); VIIRS averaged over the cone is then not what CrIS saw,
and the cost's minimum moves by tens of urad on textured scenes. Given annuli A_k (radiance means between
consecutive radii out to 0.66 deg), the VIIRS radiance CrIS would see is sum_k w_k A_k with w_k the share
of the response in annulus k (sum 1). The weights are left free, as the regression cost leaves the
calibration difference free: at the optimum they minimise the same residual variance the cost does,

    min_w  w^T M w   subject to   1^T w = 1   and a response that does not grow outwards,

with M the covariance over the samples of each annulus' difference from the CrIS BT (linearised about the
current weights), less what the cost's calibration regressors explain (a Schur complement, as in
:func:`monitor.estimation.refine.window_covariance`; :func:`response_weights` solves it). The minimum is then
sought again with V = BT(sum_k w_k A_k), and the two steps alternate until the optimum stays put
(:data:`FOOTPRINT_ITERATIONS`): a fixed point of both is a minimum of the residual over the turn and the
response jointly. A radially symmetric response cannot move the joint minimum, whatever its shape; the weights
found are the response seen on orbit (:func:`monitor.instrument.footprint.widths_of_weights`).

**The rows apart.** CrIS's FOV rows ahead (FOVs 7-9) and behind (1-3) can disagree by hundreds of urad
in-track: an error of the EP's FOV positions, or the parallax of high clouds that the collocation left.
One turn for all nine FOVs would then sit on neither row and blur the minimum. So the estimate first finds
how far apart they are (each row's own minimum through the response the unaligned FOR finds,
:func:`rows_apart`; the top-hat cone's minima disagree where the response is narrower than the cone), moves
each outer row's surfaces half of that towards the other (linear interpolation, sub-step), and estimates the
FOR on the rows thus aligned: the FOR offset is the rows' common turn, and the rows' product is what the day's
surface still finds apart plus the move.

**The uncertainty** is the delete-one-granule jackknife (:mod:`monitor.estimation.jackknife`): each replicate
repeats the estimate (its own weights, its own refined minimum) without one granule (a run of consecutive
granules on a day of more than :data:`~monitor.estimation.jackknife.MAX_GROUPS`), so the scene-to-scene part
of the error enters by construction.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from monitor.core.constants import DEFAULT_STEP_RAD
from monitor.core.result import (
    FLAG_EDGE,
    FLAG_FLAT,
    FLAG_UNCONVERGED,
)
from monitor.core.vocabulary import Cost
from monitor.estimation import refine
from monitor.estimation.cost import calibration_regressors, cost_surface, find_minimum
from monitor.estimation.intercal import (
    NO_FIT,
    Intercalibration,
    collocation_spread_k,
    intercalibrate,
    reach_steps,
)
from monitor.estimation.jackknife import Jackknife
from monitor.instrument.footprint import monotone_weights, widths_of_weights
from monitor.instrument.spectral import BandModel

FOOTPRINT_ITERATIONS = 40  # alternations of the response fit and the refined minimum in a window, at most
FOOTPRINT_WINDOWS = 3  # windows the alternation may move through as the grid minimum moves, at most
CONVERGED_STEPS = refine.ZOOMS[-1] / 2  # the optimum did not move by one step of the refinement: it stops
MIN_FOOTPRINT_SAMPLES = 40  # fewer samples than this (the estimate is flagged few_samples below 30) fit none
SLOPE_STEP = 1e-4  # relative radiance step of dBT/dL


@dataclass(frozen=True)
class ForSamples:
    """One FOR's N samples over a day: *d_k* (N, m, m) VIIRS - CrIS BT (K) at every perturbation through
    the top-hat cone, *cris_k* (N,) the CrIS BT, *granule* and *scan* (N,) where each comes from; with the
    footprint, *annuli_rad* (N, K, m, m) the VIIRS radiance means in the annuli whose outer radii are
    *radii_rad* (K,), and *band* to turn radiances into BT."""

    d_k: np.ndarray
    cris_k: np.ndarray
    granule: np.ndarray
    scan: np.ndarray
    annuli_rad: np.ndarray | None = None
    radii_rad: tuple[float, ...] = ()
    band: BandModel | None = field(default=None, repr=False)
    fov: np.ndarray | None = None  # (N,) the FOV (0..8) of each sample, for the rows (FOV_ROWS)

    def __len__(self) -> int:
        return len(self.cris_k)

    @property
    def footprint(self) -> bool:
        """Whether the samples carry annuli, so that the response is fitted.

        Returns
        -------
        bool
            True with annuli.
        """
        return self.annuli_rad is not None


@dataclass(frozen=True)
class Footprint:
    """The response fitted at a FOR's optimum: the share *weights* (K,) of each annulus (outer radii
    *radii_rad*), and the full widths (rad) at 50 and 10 % of the peak they describe, with jackknife
    sigmas (NaN without)."""

    radii_rad: tuple[float, ...]
    weights: np.ndarray
    width_50_rad: float
    width_10_rad: float
    sigma_width_50_rad: float = float("nan")
    sigma_width_10_rad: float = float("nan")


@dataclass(frozen=True)
class ForEstimate:
    """The estimate of one FOR: offsets *x*, *y* (grid steps from the centre) and their jackknife sigmas
    (steps; NaN without), *flags*, the *cost* surface (m, m, K) at the response found, *d_opt* (N,) the
    samples' BT difference at the optimum, whether it is *refined* between grid points, the
    *intercalibration* there and the *footprint* (None without annuli, or where the minimum was not
    refined)."""

    x: float
    y: float
    sigma: tuple[float, float]
    flags: list[str]
    cost: np.ndarray
    d_opt: np.ndarray
    refined: bool
    intercalibration: Intercalibration = NO_FIT
    footprint: Footprint | None = None
    rows: tuple[float, float] = (np.nan, np.nan)  # the rows ahead minus behind (steps), FOV_ROWS
    rows_sigma: tuple[float, float] = (np.nan, np.nan)
    # the offsets' jackknife replicates (G, 2) and the first and last granule each leaves out (G, 2), where
    # the groups are granules or runs of them: the day's correlation of consecutive granules is estimated
    # from them (jackknife.py)
    replicates: np.ndarray | None = None
    granules: np.ndarray | None = None
    cone: tuple[float, float] = (
        np.nan,
        np.nan,
    )  # the top-hat cone's minimum (steps), where a response was fitted


# the FOV rows (0-based FOV indices) whose offsets are told apart: those ahead and behind along-track
FOV_ROWS = ((6, 7, 8), (0, 1, 2))


def _rows(d: np.ndarray, s: ForSamples, cost: Cost, contrast: float, counts: np.ndarray) -> np.ndarray:
    """The offset (x, y in steps) of the rows ahead minus that of the rows behind (:data:`FOV_ROWS`),
    each the minimum of its own samples' surface *d* (the day's, through the response found), for every
    row of *counts* (B, N): the day (ones) and its jackknife replicates at once, one weighted surface each
    (:func:`cost_surface`), refined by the quadratic through the 3 x 3 about the grid minimum
    (:func:`find_minimum`). (B, 2); NaN where either row has fewer than 3 samples or no clear minimum."""
    assert s.fov is not None
    xy = []
    for fovs in FOV_ROWS:
        w = counts * np.isin(s.fov, fovs)
        surfaces = cost_surface(d, s.cris_k, cost, w)
        found = []
        for g, n in zip(surfaces, (w > 0).sum(axis=1), strict=True):
            x, y, flags = find_minimum(g, contrast) if n >= 3 else (np.nan, np.nan, [FLAG_FLAT])
            found.append((np.nan, np.nan) if FLAG_FLAT in flags or FLAG_EDGE in flags else (x, y))
        xy.append(np.array(found))
    return xy[0] - xy[1]


@dataclass(frozen=True)
class _Minimum:
    """Where a cost surface *g* is least: (x, y) steps from the centre, the grid minimum (i0, j0), the
    sub-step offset (dx, dy) from it where *refined*, and the flags."""

    g: np.ndarray
    x: float
    y: float
    i0: int
    j0: int
    dx: float
    dy: float
    refined: bool
    flags: list[str]


def _minimum(d: np.ndarray, cris: np.ndarray, cost: Cost, contrast: float) -> _Minimum:
    """The minimum of the cost of the differences *d* (N, m, m): on the grid, then refined between grid
    points where the window fits and the surface is neither flat nor edged
    (:mod:`monitor.estimation.refine`)."""
    m = d.shape[1]
    g = cost_surface(d, cris, cost)
    x, y, flags = find_minimum(g, contrast)
    i0, j0 = (int(k) for k in np.unravel_index(np.argmin(g), g.shape)) if np.isfinite(g).all() else (0, 0)
    fine = FLAG_EDGE not in flags and FLAG_FLAT not in flags and refine.refinable(i0, j0, m)
    dx = dy = 0.0
    if fine:
        regress = calibration_regressors(cris) if cost == Cost.REGRESSION else None
        dx, dy = refine.refined_minimum(refine.window_covariance(d, i0, j0, cris=regress))
        x, y = i0 - (m - 1) // 2 + dx, j0 - (m - 1) // 2 + dy
    return _Minimum(g, x, y, i0, j0, float(dx), float(dy), fine, flags)


def response_weights(
    annuli_rad: np.ndarray,
    cris_k: np.ndarray,
    at: _Minimum,
    cost: Cost,
    radii_rad: tuple[float, ...],
    band: BandModel,
    weights: np.ndarray | None = None,
) -> np.ndarray:
    """The annulus weights, sum 1, that minimise the residual variance of the cost's difference at the
    optimum.

    The difference is linear in w about the current V = sum_k w_k A_k: BT(V) + s (A_k - V) - C for annulus k,
    s = dBT/dL at V, so that M is the covariance of these over the samples, less what the cost's calibration
    regressors explain (a Schur complement). In BT, as the cost is: a CrIS-VIIRS bias, gain or curvature
    leaves the weights as they were. The response stays monotone
    (:func:`monitor.instrument.footprint.monotone_weights`).

    Parameters
    ----------
    annuli_rad : numpy.ndarray
        The samples' VIIRS radiance means in each annulus at every perturbation, shape (N, K, m, m).
    cris_k : numpy.ndarray
        The samples' CrIS BT, K, shape (N,).
    at : _Minimum
        The refined optimum.
    cost : Cost
        The cost (``assessment.cost``).
    radii_rad : tuple of float
        The annuli's outer radii, rad.
    band : BandModel
        The satellite's I5 band (radiance to BT).
    weights : numpy.ndarray, optional
        The current weights (K,); None: the annuli's solid angles, a top hat out to the last.

    Returns
    -------
    numpy.ndarray
        The weights, shape (K,), of a response that does not grow outwards.
    """
    a = np.stack(
        [
            refine.window_values(annuli_rad[:, k], at.i0, at.j0, at.dx, at.dy)
            for k in range(annuli_rad.shape[1])
        ],
        axis=1,
    ).astype(float)
    r_out = np.asarray(radii_rad, float)
    area = r_out**2 - np.concatenate([[0.0], r_out[:-1]]) ** 2
    v = a @ (area / area.sum() if weights is None else weights)
    bt_v = band.bt_from_radiance(v)
    slope = (band.bt_from_radiance(v * (1 + SLOPE_STEP)) - bt_v) / (v * SLOPE_STEP)
    c = np.asarray(cris_k, float)
    z = bt_v[:, None] + slope[:, None] * (a - v[:, None]) - c[:, None]
    if cost == Cost.REGRESSION:
        z = np.concatenate([z, calibration_regressors(c)], axis=1)
    zc = z - z.mean(axis=0)
    s = zc.T @ zc
    k = a.shape[1]
    m = s[:k, :k] - s[:k, k:] @ np.linalg.solve(s[k:, k:], s[k:, :k]) if s.shape[0] > k else s
    return monotone_weights(m, radii_rad)


def _with_footprint(s: ForSamples, weights: np.ndarray) -> np.ndarray:
    """The samples' VIIRS - CrIS BT (N, m, m) with V the BT of the annuli weighted by *weights*."""
    assert s.annuli_rad is not None and s.band is not None
    v = np.einsum("nkij,k->nij", s.annuli_rad, weights)
    return (s.band.bt_from_radiance(v) - s.cris_k[:, None, None]).astype(np.float64)


def _estimate(
    s: ForSamples,
    cost: Cost,
    contrast: float,
    counts: np.ndarray | None = None,
    start: np.ndarray | None = None,
    start_d: np.ndarray | None = None,
) -> tuple[_Minimum, np.ndarray | None, np.ndarray]:
    """The minimum of the samples (weighted by *counts*, a replicate: the left-out granule's rows dropped)
    and the annulus weights found there (None without annuli or a refined minimum); *start*, weights to
    begin the alternation from (a replicate starts from the day's), and *start_d* the day's surface through
    them (N, m, m): a replicate's first surface is its rows of it, not computed again."""
    keep = slice(None) if counts is None else counts > 0
    d, c = s.d_k[keep], s.cris_k[keep]
    # the day fits the footprint from MIN_FOOTPRINT_SAMPLES on; a replicate fits it whenever the day did
    # (its few samples fewer never switch it to the cone)
    fits = len(c) >= MIN_FOOTPRINT_SAMPLES if counts is None else start is not None
    annuli = s.annuli_rad[keep] if s.annuli_rad is not None and fits else None
    fit = annuli is not None
    sub = ForSamples(d, c, s.granule[keep], s.scan[keep], annuli, s.radii_rad, s.band)
    if fit and start is not None:  # the day's weights: the minimum through them (not the top-hat cone's)
        d = start_d[keep] if start_d is not None else _with_footprint(sub, start)
    best = _minimum(d, c, cost, contrast)
    if not fit or not best.refined:
        return best, None, d
    assert annuli is not None and s.band is not None
    regress = calibration_regressors(c) if cost == Cost.REGRESSION else None
    weights = start
    converged = False
    for _ in range(FOOTPRINT_WINDOWS):
        # the alternation within the refinement's window about the grid minimum: cheap (no cost surface)
        h, i0, j0 = refine.HALF, best.i0, best.j0
        window = annuli[:, :, i0 - h : i0 + h + 1, j0 - h : j0 + h + 1]
        at = best
        for _ in range(FOOTPRINT_ITERATIONS):
            weights = response_weights(annuli, c, at, cost, s.radii_rad, s.band, weights)
            d_win = s.band.bt_from_radiance(np.einsum("nkij,k->nij", window, weights)) - c[:, None, None]
            dx, dy = refine.refined_minimum(refine.window_covariance(d_win, h, h, cris=regress))
            moved = max(abs(dx - at.dx), abs(dy - at.dy))
            at = replace(at, dx=float(dx), dy=float(dy), x=at.x + dx - at.dx, y=at.y + dy - at.dy)
            converged = moved < CONVERGED_STEPS
            if converged:
                break
        # the whole surface with the weights found: the grid minimum where it was, or the window moves
        assert weights is not None  # the alternation ran at least once
        d = _with_footprint(sub, weights)
        moved_to = _minimum(d, c, cost, contrast)
        if not moved_to.refined:  # flat or at the edge through the response found: said, not dropped
            return _flagged(best, moved_to.flags, converged), weights, d
        if (moved_to.i0, moved_to.j0) == (i0, j0):
            return _flagged(moved_to, [], converged), weights, d
        best = moved_to
    return _flagged(best, [FLAG_UNCONVERGED], False), weights, d  # the windows ran out


def fitted_response(s: ForSamples, cost: Cost, contrast: float = 0.03) -> np.ndarray | None:
    """The annulus weights the FOR's samples find at their minimum.

    Parameters
    ----------
    s : ForSamples
        One FOR's samples.
    cost : Cost
        The cost (``assessment.cost``).
    contrast : float
        The relative rise from the minimum to the grid's border below which a surface is flagged ``flat``.

    Returns
    -------
    numpy.ndarray or None
        The weights (K,); None without annuli, with too few samples or no refined minimum.
    """
    return _estimate(s, cost, contrast)[1]


def through(s: ForSamples, weights: np.ndarray) -> ForSamples:
    """The samples with their surface the VIIRS minus CrIS BT through annulus weights, not the top-hat cone.

    Parameters
    ----------
    s : ForSamples
        One FOR's samples.
    weights : numpy.ndarray
        The annulus weights, shape (K,).

    Returns
    -------
    ForSamples
        The same samples.
    """
    return replace(s, d_k=_with_footprint(s, weights))


def _flagged(at: _Minimum, flags: list[str], converged: bool) -> _Minimum:
    """*at* with *flags* added, and :data:`FLAG_UNCONVERGED` unless the alternation *converged*."""
    more = flags + ([] if converged else [FLAG_UNCONVERGED])
    return replace(at, flags=sorted(set(at.flags + more))) if more else at


def rows_apart(s: ForSamples, cost: Cost, contrast: float = 0.03) -> tuple[float, float]:
    """The steps from the FOV rows behind to the rows ahead, each row's own minimum of the surface.

    Parameters
    ----------
    s : ForSamples
        One FOR's samples.
    cost : Cost
        The cost (``assessment.cost``).
    contrast : float
        The relative rise from the minimum to the grid's border below which a surface is flagged ``flat``.

    Returns
    -------
    tuple of float
        (x, y), grid steps; (0, 0) where either row has fewer than 3 samples or no clear minimum.
    """
    if s.fov is None:
        return 0.0, 0.0
    found = []
    for fovs in FOV_ROWS:
        sel = np.isin(s.fov, fovs)
        x, y, flags = (
            find_minimum(cost_surface(s.d_k[sel], s.cris_k[sel], cost), contrast)
            if sel.sum() >= 3
            else (0, 0, [FLAG_FLAT])
        )
        if FLAG_FLAT in flags or FLAG_EDGE in flags:
            return 0.0, 0.0
        found.append((x, y))
    return found[0][0] - found[1][0], found[0][1] - found[1][1]


def aligned(s: ForSamples, apart: tuple[float, float]) -> ForSamples:
    """The samples with the outer rows moved to meet at their common turn.

    Parameters
    ----------
    s : ForSamples
        One FOR's samples.
    apart : tuple of float
        The rows' separation (:func:`rows_apart`), grid steps.

    Returns
    -------
    ForSamples
        The rows ahead's surfaces moved by -apart/2 and the rows behind's by +apart/2 (linear interpolation,
        held at the grid's edge).
    """
    if s.fov is None or apart == (0.0, 0.0):
        return s
    d, annuli = s.d_k.copy(), None if s.annuli_rad is None else s.annuli_rad.copy()
    for fovs, sign in zip(FOV_ROWS, (1.0, -1.0), strict=True):
        sel = np.isin(s.fov, fovs)
        move = (-sign * 0.5 * apart[0], -sign * 0.5 * apart[1])  # out(t) = in(t + apart/2) ahead
        d[sel] = shifted(s.d_k[sel], move)
        if annuli is not None and s.annuli_rad is not None:
            annuli[sel] = shifted(s.annuli_rad[sel], move)
    return replace(s, d_k=d, annuli_rad=annuli)


def _shifted_along(a: np.ndarray, move: float, axis: int) -> np.ndarray:
    """*a* moved by *move* steps along *axis*: out[i] = a(i - move), linear between nodes, the edge value
    beyond them."""
    n = a.shape[axis]
    x = np.clip(np.arange(n) - move, 0, n - 1)
    lo = np.minimum(np.floor(x).astype(int), n - 2) if n > 1 else np.zeros(n, int)
    t = (x - lo).reshape((-1,) + (1,) * (a.ndim - axis % a.ndim - 1))
    hi = np.minimum(lo + 1, n - 1)
    below, above = np.take(a, lo, axis=axis), np.take(a, hi, axis=axis)
    return below + t * (above - below)


def shifted(a: np.ndarray, move: tuple[float, float]) -> np.ndarray:
    """Surfaces moved across the grid, held at its edge.

    Parameters
    ----------
    a : numpy.ndarray
        Values on the perturbation grid in the last two axes, shape (..., m, m).
    move : tuple of float
        The move along the two grid axes (in-track, cross-track), grid steps: out(i, j) = a(i - move[0],
        j - move[1]), bilinear between grid points, the edge value beyond the grid.

    Returns
    -------
    numpy.ndarray
        The moved values, the shape and type of *a*.
    """
    out = _shifted_along(_shifted_along(a, move[0], -2), move[1], -1)
    return out.astype(a.dtype, copy=False)


def estimate(
    s: ForSamples,
    cost: Cost,
    contrast: float = 0.03,
    uncertainty: bool = True,
    reach: int = reach_steps(DEFAULT_STEP_RAD),
) -> ForEstimate:
    """Offsets, jackknife sigmas, flags, the intercalibration and the footprint of one FOR's samples.

    Parameters
    ----------
    s : ForSamples
        One FOR's samples.
    cost : Cost
        The cost (``assessment.cost``).
    contrast : float
        The relative rise from the minimum to the grid's border below which a surface is flagged ``flat``.
    uncertainty : bool
        Whether to compute the jackknife sigmas.
    reach : int
        The turns (grid steps) about the optimum within which the intercalibration reads each sample's
        collocation spread (:mod:`monitor.estimation.intercal`).

    Returns
    -------
    ForEstimate
        The FOR's estimate, its rows aligned first (:func:`aligned`).
    """
    start, apart = None, (0.0, 0.0)
    if s.fov is not None:
        # the rows apart on the surface through the response the unaligned rows find: the top-hat cone's
        # rows disagree where the response is narrower than the cone (studies/footprint.md)
        _, start, d0 = _estimate(s, cost, contrast)
        apart = rows_apart(s if start is None else replace(s, d_k=d0), cost, contrast)
        s = aligned(s, apart)
    best, weights, d = _estimate(s, cost, contrast, start=start)
    d_opt = (
        refine.window_values(d, best.i0, best.j0, best.dx, best.dy)
        if best.refined
        else d[:, best.i0, best.j0]
    )
    jack = Jackknife.of(s.granule, s.scan) if uncertainty else None
    replicates = None
    rows = rows_sigma = (np.nan, np.nan)
    sigma = (np.nan, np.nan)
    cal_boot = None
    fp = None
    cone = (np.nan, np.nan)
    if weights is not None:
        widths = widths_of_weights(s.radii_rad, weights)
        fp = Footprint(s.radii_rad, weights, widths[0.5], widths[0.1])
        top_hat = _minimum(s.d_k, s.cris_k, cost, contrast)
        cone = (top_hat.x, top_hat.y)
    if s.fov is not None:  # the rows, the day's and its replicates', on the day's surface
        counts = np.ones((1, len(s))) if jack is None else np.vstack([np.ones(len(s)), jack.counts])
        found = _rows(d, s, cost, contrast, counts) + np.asarray(apart)
        rows = (float(found[0, 0]), float(found[0, 1]))
        if jack is not None:
            rs = jack.sigma(found[1:])
            rows_sigma = (float(rs[0]), float(rs[1]))
    if jack is not None:
        reps, vs, width_reps = [], [], []
        for counts in jack.counts:
            b, w_b, d_b = _estimate(s, cost, contrast, counts, weights, d if weights is not None else None)
            reps.append((b.x, b.y))
            # the intercalibration at the replicate's own optimum, over the samples it kept (the others weigh
            # nothing: any finite value serves)
            v_b = d_opt + s.cris_k
            keep = counts > 0
            v_b[keep] = (
                refine.window_values(d_b, b.i0, b.j0, b.dx, b.dy) if b.refined else d_b[:, b.i0, b.j0]
            ) + s.cris_k[keep]
            vs.append(v_b)
            if w_b is not None:
                wb = widths_of_weights(s.radii_rad, w_b)
                width_reps.append((wb[0.5], wb[0.1]))
            else:
                width_reps.append((np.nan, np.nan))
        replicates = np.array(reps)
        sig = jack.sigma(replicates)
        sigma = (float(sig[0]), float(sig[1]))
        cal_boot = np.array(vs)
        if fp is not None:
            ws = jack.sigma(np.array(width_reps))
            fp = Footprint(
                fp.radii_rad, fp.weights, fp.width_50_rad, fp.width_10_rad, float(ws[0]), float(ws[1])
            )
    spread = collocation_spread_k(d, best.i0, best.j0, reach)
    cal = intercalibrate(s.cris_k, d_opt + s.cris_k, spread, jack, cal_boot)
    return ForEstimate(
        best.x, best.y, sigma, best.flags, best.g, d_opt, best.refined, cal, fp,
        rows, rows_sigma, replicates, None if jack is None else jack.granules, cone,
    )  # fmt: skip
