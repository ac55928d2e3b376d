"""CrIS-VIIRS intercalibration at the geolocation optimum: the BT bias at a reference temperature, the gain.

At a FOR's optimum perturbation the VIIRS cone mean V_n (the I5 BT of the VIIRS radiance averaged over the
perturbed CrIS FOV n) and the CrIS BT C_n convolved with the I5 response see the same scene; what separates
them, once the geolocation is right, is the calibration difference of the two instruments and their noise.
To first order about a reference temperature T_ref (``CALIBRATION_REFERENCE_K``, 280 K),

    C_n - V_n = b + g (V_n - T_ref) + e_n,

with b the CrIS-VIIRS bias at T_ref (K) and g the relative gain difference (reported in per cent): the
simulator's calibration law (:class:`monitor.simulate.case.SimulationSpec`) and the seeds'
CrIS/VIIRS intercalibration plots in one line. V is the regressor because it is the better measured of
the two (a mean over some hundred I5 pixels against one CrIS spectrum), so ordinary least squares is not
attenuated by its noise. A non-linear difference (a curvature in T) is not modelled: the fit then gives the
secant over the day's scenes, and :func:`difference_bins` (the paper's Figure 15: C - V against C in 10 K
bins) shows the shape.

The sigmas resample the same scans as the offsets' bootstrap (:func:`monitor.assess.for_minimum`): the
weighted fit on each replicate's counts, the spread of the replicates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monitor.constants import CALIBRATION_BIN_K, CALIBRATION_REFERENCE_K
from monitor.result import DifferenceBin


@dataclass(frozen=True)
class Intercalibration:
    """CrIS minus VIIRS at one FOR: the bias (K) at ``CALIBRATION_REFERENCE_K`` and the gain (per cent of
    the BT's departure from it), with their bootstrap sigmas (NaN without a bootstrap)."""

    bias_k: float
    sigma_bias_k: float
    gain_pct: float
    sigma_gain_pct: float


NO_FIT = Intercalibration(np.nan, np.nan, np.nan, np.nan)


def bias_and_gain(cris_k, viirs_k, weights=None):
    """Least-squares (b_k, g) of C - V = b + g (V - T_ref) over samples (the last axis of *cris_k* and
    *viirs_k*, (N,)); with *weights* (B, N), e.g. bootstrap counts, one fit per row ((B,), (B,))."""
    x = np.asarray(viirs_k, float) - CALIBRATION_REFERENCE_K
    y = np.asarray(cris_k, float) - np.asarray(viirs_k, float)
    w = np.ones((1, x.size)) if weights is None else np.asarray(weights, float)
    s0 = w.sum(axis=1)
    mx, my = (w @ x) / s0, (w @ y) / s0
    xc, yc = x[None] - mx[:, None], y[None] - my[:, None]
    with np.errstate(invalid="ignore", divide="ignore"):
        g = np.sum(w * xc * yc, axis=1) / np.sum(w * xc * xc, axis=1)
    b = my - g * mx
    return (b[0], g[0]) if weights is None else (b, g)


def intercalibrate(cris_k, viirs_k, counts=None) -> Intercalibration:
    """The bias and gain of one FOR's samples at its optimum, sigmas from the bootstrap *counts* (B, N)."""
    if len(cris_k) < 3:
        return NO_FIT
    b, g = bias_and_gain(cris_k, viirs_k)
    sig_b = sig_g = np.nan
    if counts is not None and len(counts) > 1:
        bb, gg = bias_and_gain(cris_k, viirs_k, counts)
        sig_b, sig_g = float(np.nanstd(bb)), float(np.nanstd(gg))
    return Intercalibration(float(b), sig_b, 100.0 * float(g), 100.0 * sig_g)


def difference_bins(cris_k, viirs_k) -> list[DifferenceBin]:
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
