"""CrIS-VIIRS intercalibration at the geolocation optimum, on the scenes the collocation cannot move: the
BT bias at a reference temperature, the gain and the curvature there.

**The law.** At a FOR's optimum perturbation the VIIRS cone mean V_n (the I5 BT of the VIIRS radiance
averaged over the perturbed CrIS FOV n) and the CrIS BT C_n convolved with the I5 response see nearly the
same scene. To second order about a reference temperature T_ref (``CALIBRATION_REFERENCE_K``, 280 K for
every satellite, so that the stored series and ``calibration_jump`` keep one meaning), with x = V_n - T_ref
and S = ``CALIBRATION_CURVATURE_SPAN_K`` (30 K),

    C_n - V_n = b + g x + c (x / S)^2 + e_n,

b is the CrIS-VIIRS bias at T_ref (K), g the gain difference there (relative; reported in per cent) and c the
curvature (K: what it adds at 250 and 310 K): the simulator's calibration law
(:class:`monitor.simulate.case.SimulationSpec`) and the seeds' intercalibration plots in one line.

**What the collocation puts in e_n** (inter-calibration practice, GSICS: compare only where the collocation
cannot matter). The cone mean is not what CrIS saw: the optimum is uncertain, the outer FOV rows see high
clouds from elsewhere (parallax), and the CrIS response reaches past the cone's edge. Each moves the VIIRS
mean by at most how much the cone mean changes when the cone moves by that much. The response's skirt is
the farthest of the three: the specification's 3 %-of-peak width (``footprint.SPEC_WIDTHS``, 1.238 deg)
reaches ``REACH_RAD`` (~2.4 mrad) beyond the cone's radius. So each sample's *collocation spread*
s_n = max |V(turn) - V(optimum)| over the turns within that reach (:func:`collocation_spread_k`) bounds what
the collocation adds to V_n: a uniform scene has s_n at its noise, a cloud edge kelvins. Regressing C - V on
V over every scene read that mismatch as calibration (a gain diluted by -var(e)/var(V): -2.8 % on the real
collocations).

**Errors in both variables.** C_n carries its noise sigma_0; V_n its own noise and what the collocation put
in, a part kappa of its spread: sigma_0^2 + kappa^2 s_n^2. V enters both sides of the law, so the residual's
variance is the *effective variance* (Orear 1982, errors in both variables for a model linear in its
parameters; for a straight line, York's regression):

    var_n = sigma_0^2 + (1 + g + 2 c x_n / S^2)^2 (sigma_0^2 + kappa^2 s_n^2),

and the law is fitted by least squares weighted 1 / var_n, the slope factor updated once from a first fit.
No threshold is chosen: the weights are the uniformity test in its continuous form, and sigma_0 and kappa
are not assumed but found from the day's residuals by maximum likelihood (:func:`variance_scale`). On the
simulated days kappa comes out near 0.01 (the optimum is good to a few urad, so the collocation moves V by a
hundredth of what the reach would); a cloud edge of s_n = 3 K then weighs as a uniform scene at 0.03 K.

**A gain only where the scenes determine it.** A day of warm ocean alone (uniform scenes within a few K)
determines a bias but not a gain. The gain (and curvature) are stated where the sigma of the gain (the
jackknife's, else the fit's) is at most ``GAIN_RESOLUTION_PCT`` (the 0.1 % to which the product claims to
recover a gain); elsewhere only the bias is fitted (g = c = 0: the mean difference of the weighted scenes,
stated at T_ref on the assumption of no gain) and the gain is NaN, flagged ``gain_undetermined`` by the
estimator. :func:`difference_bins` (the paper's Figure 15: C - V against C in 10 K bins, every scene) shows
the shape.

The sigmas come from the same delete-one-granule jackknife as the offsets'
(:mod:`monitor.estimation.jackknife`): the fit on each replicate's samples at that replicate's own optimum,
with the day's variances.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy import optimize

from monitor.core.constants import (
    CALIBRATION_BIN_K,
    CALIBRATION_CURVATURE_SPAN_K,
    CALIBRATION_REFERENCE_K,
    FOV_HALF_ANGLE_RAD,
)
from monitor.core.result import DifferenceBin
from monitor.estimation.jackknife import Jackknife
from monitor.instrument.footprint import SPEC_WIDTHS

MAX_CONDITION = 1e10  # a fit whose normal equations are worse conditioned (no BT spread) gives NaN
# how far past the cone's radius the response reaches: half the specification's widest width (3 % of peak)
REACH_RAD = max(hi for _, _, hi in SPEC_WIDTHS if hi is not None) / 2 - FOV_HALF_ANGLE_RAD
GAIN_RESOLUTION_PCT = 0.1  # a gain known worse than this (the fit's sigma) is not stated
# sigma_0 is kept above this (K), so that a sample whose cone mean does not change at all does not weigh
# without bound: below any instrument's noise (the real collocations' bias moves by < 0.01 K for floors of
# 0.001-0.03 K)
NOISE_FLOOR_K = 1e-3
MIN_SAMPLES = 4


@dataclass(frozen=True)
class Intercalibration:
    """CrIS minus VIIRS at one FOR: the bias (K) at ``CALIBRATION_REFERENCE_K``, the gain there (per cent of
    the BT's departure from it) and the curvature (K at ``CALIBRATION_CURVATURE_SPAN_K`` from it), with
    their jackknife sigmas (NaN without); the gain and curvature NaN where the scenes do not determine them
    (module docstring)."""

    bias_k: float
    sigma_bias_k: float
    gain_pct: float
    sigma_gain_pct: float
    curvature_k: float
    sigma_curvature_k: float

    def sigmas_scaled(self, factor: float) -> Intercalibration:
        """The same fit with every sigma times a factor (the jackknife's count of independent granules).

        Parameters
        ----------
        factor : float
            The factor.

        Returns
        -------
        Intercalibration
            The scaled fit.
        """
        return replace(
            self,
            sigma_bias_k=factor * self.sigma_bias_k,
            sigma_gain_pct=factor * self.sigma_gain_pct,
            sigma_curvature_k=factor * self.sigma_curvature_k,
        )

    @property
    def gain_undetermined(self) -> bool:
        """Whether a bias was fitted but the scenes' temperatures could not determine a gain.

        Returns
        -------
        bool
            True then.
        """
        return math.isfinite(self.bias_k) and not math.isfinite(self.gain_pct)


NO_FIT = Intercalibration(*[np.nan] * 6)


def reach_steps(step_rad: float) -> int:
    """The turns that cover ``REACH_RAD`` about the optimum.

    Parameters
    ----------
    step_rad : float
        The perturbation step, rad.

    Returns
    -------
    int
        Grid steps.
    """
    return max(1, math.ceil(REACH_RAD / step_rad - 1e-9))


def collocation_spread_k(d_k: np.ndarray, i0: int, j0: int, reach: int) -> np.ndarray:
    """Per sample, the most its cone mean changes over the turns within reach of the optimum.

    Parameters
    ----------
    d_k : numpy.ndarray
        The samples' V - C surfaces, K, shape (N, m, m).
    i0, j0 : int
        The optimum's grid indices.
    reach : int
        The turns each side, a square clipped to the grid (:func:`reach_steps`).

    Returns
    -------
    numpy.ndarray
        K, shape (N,): what the collocation can put into V there; infinite where a turn has no cone mean (the
        sample then weighs nothing).
    """
    m = d_k.shape[1]
    window = d_k[:, max(0, i0 - reach) : min(m, i0 + reach + 1), max(0, j0 - reach) : min(m, j0 + reach + 1)]
    spread = np.abs(window - d_k[:, i0, j0][:, None, None]).max(axis=(1, 2))
    return np.where(np.isnan(spread), np.inf, spread)


def _design(viirs_k: np.ndarray, terms: int) -> np.ndarray:
    """The law's regressors (..., N, terms): 1, x, (x / S)^2, x = V - T_ref."""
    x = viirs_k - CALIBRATION_REFERENCE_K
    return np.stack([np.ones_like(x), x, (x / CALIBRATION_CURVATURE_SPAN_K) ** 2][:terms], axis=-1)


def _solve(a: np.ndarray, y: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weighted least squares per row of *w* (B, N): the parameters (B, p) (NaN where the normal equations
    are singular) and their covariances (B, p, p) for weights that are inverse variances."""
    normal = np.einsum("bn,bni,bnj->bij", w, a, a)
    rhs = np.einsum("bn,bni,bn->bi", w, a, y)
    p = a.shape[-1]
    out, cov = np.full((len(w), p), np.nan), np.full((len(w), p, p), np.nan)
    ok = np.linalg.cond(normal) < MAX_CONDITION
    if ok.any():
        out[ok] = np.linalg.solve(normal[ok], rhs[ok][..., None])[..., 0]
        cov[ok] = np.linalg.inv(normal[ok])
    return out, cov


def _variance(
    viirs_k: np.ndarray, spread_k: np.ndarray, scale: tuple[float, float], beta: np.ndarray
) -> np.ndarray:
    """The effective variance (K^2) of each residual for the noise and spread factor *scale* and the
    parameters *beta* (B, p) (module docstring)."""
    noise, kappa = scale
    x = viirs_k - CALIBRATION_REFERENCE_K
    slope = np.ones(np.broadcast_shapes(x.shape, (len(beta), 1)))
    if beta.shape[-1] > 1:
        slope = slope + beta[:, 1:2]
    if beta.shape[-1] > 2:
        slope = slope + 2 * beta[:, 2:3] * x / CALIBRATION_CURVATURE_SPAN_K**2
    return noise**2 + np.nan_to_num(slope, nan=1.0) ** 2 * (noise**2 + (kappa * spread_k) ** 2)


def fit_difference(
    cris_k: np.ndarray,
    viirs_k: np.ndarray,
    spread_k: np.ndarray,
    scale: tuple[float, float],
    counts: np.ndarray | None = None,
    terms: int = 3,
) -> tuple[np.ndarray, np.ndarray]:
    """The law's first parameters (b_k, g, c_k) fitted with effective-variance weights.

    The weights' slope factor comes from a first fit.

    Parameters
    ----------
    cris_k, viirs_k : numpy.ndarray
        The samples' CrIS BT and VIIRS cone mean at the optimum, K, shape (N,).
        *viirs_k* may be (B, N): one V per row.
    spread_k : numpy.ndarray
        The samples' collocation spreads (:func:`collocation_spread_k`), K, shape (N,).
    scale : tuple of float
        The variance model's sigma_0 (K) and kappa (:func:`variance_scale`).
    counts : numpy.ndarray, optional
        Replicate weights, shape (B, N): one fit per row.
    terms : int
        1 (the bias), 2 (and the gain) or 3 (and the curvature).

    Returns
    -------
    params, covariance : numpy.ndarray
        Shapes (p,) and (p, p), or (B, p) and (B, p, p); the bias in K, the gain as a fraction, the curvature
        in K.
    """
    one = counts is None
    w0 = np.ones((1, len(cris_k))) if one else np.asarray(counts, float)
    v = np.broadcast_to(np.asarray(viirs_k, float), w0.shape)
    y = np.asarray(cris_k, float) - v
    a = _design(v, terms)
    beta = np.zeros((len(w0), terms))
    for _ in range(2):
        beta, cov = _solve(a, y, w0 / _variance(v, spread_k, scale, beta))
    return (beta[0], cov[0]) if one else (beta, cov)


def variance_scale(
    cris_k: np.ndarray, viirs_k: np.ndarray, spread_k: np.ndarray, terms: int = 3
) -> tuple[float, float]:
    """The variance model's scale, sigma_0^2 + kappa^2 s_n^2, by maximum likelihood of the fit's residuals.

    Parameters
    ----------
    cris_k, viirs_k : numpy.ndarray
        The samples' CrIS BT and VIIRS cone mean at the optimum, K, shape (N,).
    spread_k : numpy.ndarray
        The samples' collocation spreads, K, shape (N,).
    terms : int
        The law's parameters, profiled out.

    Returns
    -------
    sigma_0_k, kappa : float
        NaN without degrees of freedom.
    """
    if len(cris_k) <= terms + 2:
        return math.nan, math.nan
    finite = np.isfinite(spread_k)

    def minus_log_likelihood(p: np.ndarray) -> float:
        scale = (math.exp(p[0]), math.exp(p[1]))
        beta, _ = fit_difference(cris_k, viirs_k, spread_k, scale, terms=terms)
        if not np.isfinite(beta).all():
            return 1e300  # the simplex steps back from where the normal equations fail
        r = (cris_k - viirs_k - _design(viirs_k, terms) @ beta)[finite]
        var = _variance(viirs_k, spread_k, scale, beta[None])[0][finite]
        return float(0.5 * np.sum(r * r / var + np.log(var)))

    start = np.log([max(NOISE_FLOOR_K, float(np.median(spread_k[finite])) / 10), 0.3])
    found = optimize.minimize(minus_log_likelihood, start, method="Nelder-Mead", options={"xatol": 1e-3})
    noise, kappa = np.exp(found.x)
    return max(float(noise), NOISE_FLOOR_K), float(kappa)


def intercalibrate(
    cris_k: np.ndarray,
    viirs_k: np.ndarray,
    spread_k: np.ndarray,
    jackknife: Jackknife | None = None,
    viirs_boot_k: np.ndarray | None = None,
) -> Intercalibration:
    """The bias, gain and curvature of one FOR's samples at its optimum.

    Parameters
    ----------
    cris_k, viirs_k : numpy.ndarray
        The samples' CrIS BT and VIIRS cone mean at the optimum, K, shape (N,).
    spread_k : numpy.ndarray
        The samples' collocation spreads (:func:`collocation_spread_k`), K, shape (N,).
    jackknife : Jackknife, optional
        The replicates the sigmas come from.
    viirs_boot_k : numpy.ndarray, optional
        Each replicate's V at its own optimum, K, shape (G, N).

    Returns
    -------
    Intercalibration
        No fit (NaN) from fewer than ``MIN_SAMPLES``; the gain and curvature NaN where their sigma (the
        jackknife's, else the fit's) exceeds ``GAIN_RESOLUTION_PCT``.
    """
    c, v, s = (np.asarray(a, float) for a in (cris_k, viirs_k, spread_k))
    if len(c) < MIN_SAMPLES:
        return NO_FIT
    for terms in (3, 1):
        scale = variance_scale(c, v, s, terms)
        if not math.isfinite(scale[0]):
            return NO_FIT
        beta, cov = fit_difference(c, v, s, scale, terms=terms)
        sig = np.sqrt(np.diag(cov))
        if jackknife is not None:
            v_reps = v if viirs_boot_k is None else viirs_boot_k
            sig = jackknife.sigma(fit_difference(c, v_reps, s, scale, jackknife.counts, terms)[0])
        if terms == 1 or (np.isfinite(beta).all() and 100 * sig[1] <= GAIN_RESOLUTION_PCT):
            break
    if jackknife is None:
        sig = np.full(terms, np.nan)
    b, g, cv = (*beta, np.nan, np.nan)[:3] if terms == 1 else beta
    sb, sg, sc = (*sig, np.nan, np.nan)[:3] if terms == 1 else sig
    return Intercalibration(float(b), float(sb), 100.0 * float(g), 100.0 * float(sg), float(cv), float(sc))


def difference_bins(cris_k: np.ndarray, viirs_k: np.ndarray) -> list[DifferenceBin]:
    """C - V against C in bins ``CALIBRATION_BIN_K`` wide on multiples of it (the paper's Figure 15).

    Parameters
    ----------
    cris_k, viirs_k : numpy.ndarray
        The samples' CrIS BT and VIIRS cone mean at the optimum, K, shape (N,).

    Returns
    -------
    list of DifferenceBin
        The bins with samples.
    """
    c = np.asarray(cris_k, float)
    d = c - np.asarray(viirs_k, float)
    ok = np.isfinite(c) & np.isfinite(d)
    c, d = c[ok], d[ok]
    if c.size == 0:
        return []
    idx = np.floor(c / CALIBRATION_BIN_K).astype(np.int64)
    first = int(idx.min())
    k = idx - first
    n = np.bincount(k)
    s1 = np.bincount(k, d)
    s2 = np.bincount(k, d * d)
    out = []
    for i in np.flatnonzero(n):
        mean = s1[i] / n[i]
        var = (s2[i] - n[i] * mean * mean) / (n[i] - 1) if n[i] > 1 else np.nan
        out.append(
            DifferenceBin(
                (first + int(i)) * CALIBRATION_BIN_K, int(n[i]), float(mean), float(np.sqrt(max(var, 0.0)))
            )
        )
    return out
