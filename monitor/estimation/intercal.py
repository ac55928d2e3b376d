"""CrIS-VIIRS intercalibration at the geolocation optimum: the BT bias at a reference temperature, the gain
and the curvature there.

At a FOR's optimum perturbation the VIIRS cone mean V_n (the I5 BT of the VIIRS radiance averaged over the
perturbed CrIS FOV n) and the CrIS BT C_n convolved with the I5 response see the same scene; what separates
them, once the geolocation is right, is the calibration difference of the two instruments and their noise.
To second order about a reference temperature T_ref (``CALIBRATION_REFERENCE_K``, 280 K), with
x = V_n - T_ref and S = ``CALIBRATION_CURVATURE_SPAN_K`` (30 K),

    C_n - V_n = b + g x + c (x / S)^2 + e_n,

b is the CrIS-VIIRS bias at T_ref (K), g the gain difference there (relative; reported in per cent) and c the
curvature (K: what it adds at 250 and 310 K). That is the simulator's calibration law
(:class:`monitor.simulate.case.SimulationSpec`) and the seeds' CrIS/VIIRS intercalibration plots in one line.
The curvature is fitted so that b and g are the difference *at* T_ref whatever mix of scenes a day brings:
a straight line through a curved difference would give the secant over the day's BT range, and a day of
more cloud would move it. V is the regressor because it is the better measured of the two (a mean over
some hundred I5 pixels against one CrIS spectrum), so least squares is not attenuated by its noise.
:func:`difference_bins` (the paper's Figure 15: C - V against C in 10 K bins) shows the shape.

The sigmas come from the same delete-one-granule jackknife as the offsets'
(:mod:`monitor.estimation.estimate`,
:mod:`monitor.estimation.jackknife`): the fit on each replicate's samples at that replicate's own optimum; so
a FOR whose optimum is uncertain has an uncertain intercalibration too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monitor.core.constants import CALIBRATION_BIN_K, CALIBRATION_CURVATURE_SPAN_K, CALIBRATION_REFERENCE_K
from monitor.core.result import DifferenceBin
from monitor.estimation.jackknife import Jackknife

MAX_CONDITION = 1e10  # a fit whose normal equations are worse conditioned (no BT spread) gives NaN
# The fit is stated at T_ref only where the samples reach it: T_ref within the 5th-95th percentile range of
# V, and that range at least this wide. A FOR of ocean alone (a few K around 295 K) would put a quadratic's
# value at 280 K from extrapolation, off by tenths of a K with a bootstrap sigma that cannot tell (measured
# on one simulated granule: 0.63 K off, sigma 0.04 K, from 36 samples within 288-294 K).
MIN_SPAN_K = 2 * CALIBRATION_BIN_K


@dataclass(frozen=True)
class Intercalibration:
    """CrIS minus VIIRS at one FOR: the bias (K) at ``CALIBRATION_REFERENCE_K``, the gain there (per cent of
    the BT's departure from it) and the curvature (K at ``CALIBRATION_CURVATURE_SPAN_K`` from it), with
    their jackknife sigmas (NaN without)."""

    bias_k: float
    sigma_bias_k: float
    gain_pct: float
    sigma_gain_pct: float
    curvature_k: float
    sigma_curvature_k: float


NO_FIT = Intercalibration(*[np.nan] * 6)


def fit_difference(cris_k: np.ndarray, viirs_k: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """Least-squares (b_k, g, c_k) of C - V = b + g x + c (x / S)^2, x = V - T_ref, over the samples
    *cris_k* (N,) and *viirs_k* (N,); with *weights* (B, N), e.g. bootstrap counts, one fit per row (B, 3),
    and then *viirs_k* may also be (B, N): one V per row. NaN where the samples do not span enough BT."""
    v = np.asarray(viirs_k, float)
    x = v - CALIBRATION_REFERENCE_K
    y = np.asarray(cris_k, float) - v
    a = np.stack([np.ones_like(x), x, (x / CALIBRATION_CURVATURE_SPAN_K) ** 2], axis=-1)  # (..., N, 3)
    w = np.ones((1, x.shape[-1])) if weights is None else np.asarray(weights, float)
    a, y = np.broadcast_to(a, w.shape + (3,)), np.broadcast_to(y, w.shape)
    normal = np.einsum("bn,bni,bnj->bij", w, a, a)
    rhs = np.einsum("bn,bni,bn->bi", w, a, y)
    ok = np.linalg.cond(normal) < MAX_CONDITION
    out = np.full((len(w), 3), np.nan)
    if ok.any():
        out[ok] = np.linalg.solve(normal[ok], rhs[ok][..., None])[..., 0]
    return out[0] if weights is None else out


def intercalibrate(
    cris_k: np.ndarray,
    viirs_k: np.ndarray,
    jackknife: Jackknife | None = None,
    viirs_boot_k: np.ndarray | None = None,
) -> Intercalibration:
    """The bias, gain and curvature of one FOR's samples at its optimum; sigmas from the *jackknife*'s
    replicates, each fitted at its own optimum where *viirs_boot_k* (G, N) gives the V there. No fit (NaN)
    from fewer than 4 samples, or from samples that do not reach T_ref (``MIN_SPAN_K``)."""
    if len(cris_k) < 4:
        return NO_FIT
    lo, hi = np.percentile(viirs_k, [5, 95])
    if not (lo <= CALIBRATION_REFERENCE_K <= hi and hi - lo >= MIN_SPAN_K):
        return NO_FIT
    b, g, c = fit_difference(cris_k, viirs_k)
    sig = np.full(3, np.nan)
    if jackknife is not None:
        v = viirs_k if viirs_boot_k is None else viirs_boot_k
        sig = jackknife.sigma(fit_difference(cris_k, v, jackknife.counts))
    return Intercalibration(
        float(b), float(sig[0]), 100.0 * float(g), 100.0 * float(sig[1]), float(c), float(sig[2])
    )


def difference_bins(cris_k: np.ndarray, viirs_k: np.ndarray) -> list[DifferenceBin]:
    """C - V against C in bins ``CALIBRATION_BIN_K`` wide on multiples of it (the paper's Figure 15); bins
    without samples are left out."""
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
