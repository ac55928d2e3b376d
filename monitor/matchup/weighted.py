"""The VIIRS pixels inside each CrIS FOV, weighted by the CrIS spatial response: the compiled sums.

A VIIRS pixel at ECEF point P is seen from the CrIS position S at the angle theta between unit(P - S) and
the FOV's line of sight L. It enters the FOV's mean with the weight

    w = R(theta) * Omega,   Omega = |A . u| / |P - S|^2,

R the FOV's spatial response (peak 1) and Omega the solid angle the pixel's footprint covers seen from
CrIS: A is the footprint's vector area (the cross product of the half-steps to the pixel's neighbours
along the row and across the detectors of its scan, one-sided at a scan's first and last detector or
beside a deleted pixel), u = unit(P - S). Pixels of a scan's overlap with the next (towards the swath
edge) both count: they see the same ground, so a mean is not biased, only the weight's total is
(:func:`coverage`). This is the AAPP CrIS-VIIRS mapping's weighting (each pixel by the FOV's response at
its angle), with the footprint sizes that change at the VIIRS aggregation-zone edges accounted for.

Each FOV searches a window of rows and columns about the pixel nearest its centre; the kernel runs in
parallel over FOVs, each FOV's sums its own, with numba's numpy error model.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from monitor.compiled.threads import KERNEL_LOCK

# the sums per FOV and band: weight, weight x band radiance, weight x BT, weight x BT^2, valid pixels
N_SUMS = 5
W, WL, WT, WT2, NPX = range(N_SUMS)
TABLE_SAMPLES = 512  # a response is tabulated at this many angles, uniform from 0 to its reach


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _half_step(
    pix: np.ndarray, r: int, c: int, dr: int, dc: int, r_lo: int, r_hi: int, out: np.ndarray
) -> bool:
    """The half-step (m) from pixel (r, c) to its neighbours along (dr, dc), one-sided where a neighbour is
    outside rows r_lo..r_hi (the pixel's scan), outside the row or has no position; False where neither
    neighbour has one."""
    rows, cols = pix.shape[0], pix.shape[1]
    rp, cp, rm, cm = r + dr, c + dc, r - dr, c - dc
    ok_p = r_lo <= rp <= r_hi and 0 <= cp < cols and rp < rows and not math.isnan(pix[rp, cp, 0])
    ok_m = r_lo <= rm <= r_hi and 0 <= cm < cols and rm >= 0 and not math.isnan(pix[rm, cm, 0])
    if ok_p and ok_m:
        for k in range(3):
            out[k] = 0.5 * (pix[rp, cp, k] - pix[rm, cm, k])
    elif ok_p:
        for k in range(3):
            out[k] = pix[rp, cp, k] - pix[r, c, k]
    elif ok_m:
        for k in range(3):
            out[k] = pix[r, c, k] - pix[rm, cm, k]
    else:
        return False
    return True


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _fov_sums(
    pix: np.ndarray,
    radiance: np.ndarray,
    bt_k: np.ndarray,
    good: np.ndarray,
    detectors: int,
    sat: np.ndarray,
    los: np.ndarray,
    window: np.ndarray,
    table_of: np.ndarray,
    tables: np.ndarray,
    reach: np.ndarray,
    out: np.ndarray,
) -> None:
    """Add each FOV's response-weighted sums over the pixels of its window to *out* (F, bands, N_SUMS)."""
    n_fov = sat.shape[0]
    n_band = radiance.shape[0]
    n_tab = tables.shape[1]
    for f in numba.prange(n_fov):
        r0, r1, c0, c1 = window[f, 0], window[f, 1], window[f, 2], window[f, 3]
        if r1 <= r0:
            continue
        t = table_of[f]
        cos_reach = math.cos(reach[t])
        to_index = (n_tab - 1) / reach[t]
        a = np.empty(3)
        b = np.empty(3)
        for r in range(r0, r1):
            s_lo = (r // detectors) * detectors
            s_hi = s_lo + detectors - 1
            for c in range(c0, c1):
                px, py, pz = pix[r, c, 0], pix[r, c, 1], pix[r, c, 2]
                if math.isnan(px):
                    continue
                dx, dy, dz = px - sat[f, 0], py - sat[f, 1], pz - sat[f, 2]
                d2 = dx * dx + dy * dy + dz * dz
                d = math.sqrt(d2)
                cos_t = (dx * los[f, 0] + dy * los[f, 1] + dz * los[f, 2]) / d
                if cos_t < cos_reach:
                    continue
                theta = math.acos(min(cos_t, 1.0))
                x = theta * to_index
                i = min(int(x), n_tab - 2)
                resp = tables[t, i] + (x - i) * (tables[t, i + 1] - tables[t, i])
                if resp <= 0.0:
                    continue
                if not _half_step(pix, r, c, 0, 1, s_lo, s_hi, a):
                    continue
                if not _half_step(pix, r, c, 1, 0, s_lo, s_hi, b):
                    continue
                ax = a[1] * b[2] - a[2] * b[1]
                ay = a[2] * b[0] - a[0] * b[2]
                az = a[0] * b[1] - a[1] * b[0]
                omega = abs(ax * dx + ay * dy + az * dz) / (d2 * d)
                w = resp * omega
                for k in range(n_band):
                    if not good[k, r, c]:
                        continue
                    out[f, k, W] += w
                    out[f, k, WL] += w * radiance[k, r, c]
                    out[f, k, WT] += w * bt_k[k, r, c]
                    out[f, k, WT2] += w * bt_k[k, r, c] * bt_k[k, r, c]
                    out[f, k, NPX] += 1.0


def fov_sums(
    pix_m: np.ndarray,
    radiance: np.ndarray,
    bt_k: np.ndarray,
    good: np.ndarray,
    detectors: int,
    sat_m: np.ndarray,
    los: np.ndarray,
    window: np.ndarray,
    table_of: np.ndarray,
    tables: np.ndarray,
    reach_rad: np.ndarray,
    out: np.ndarray,
) -> None:
    """Add each FOV's response-weighted sums over one VIIRS granule's pixels to *out*.

    Parameters
    ----------
    pix_m : numpy.ndarray
        The pixels' ECEF points, m, shape (rows, cols, 3), NaN where a pixel has no position.
    radiance : numpy.ndarray
        Each band's pixel band radiance, mW/(m2 sr cm-1), shape (bands, rows, cols).
    bt_k : numpy.ndarray
        Each band's pixel brightness temperature, K, shape (bands, rows, cols).
    good : numpy.ndarray
        Where a band's pixel is usable, shape (bands, rows, cols).
    detectors : int
        Rows per scan (32 I-band, 16 M-band).
    sat_m : numpy.ndarray
        Each FOV's CrIS position, ECEF, m, shape (F, 3).
    los : numpy.ndarray
        Each FOV's unit line of sight, ECEF, shape (F, 3).
    window : numpy.ndarray
        Each FOV's rows and columns searched, [r0, r1) x [c0, c1), int64 shape (F, 4).
    table_of : numpy.ndarray
        Each FOV's response table (a row of *tables*), shape (F,).
    tables : numpy.ndarray
        Responses tabulated uniformly in angle from 0 to their reach, shape (K, TABLE_SAMPLES).
    reach_rad : numpy.ndarray
        Each table's reach, rad, shape (K,).
    out : numpy.ndarray
        The sums, added to in place, shape (F, bands, N_SUMS).
    """
    with KERNEL_LOCK:
        _fov_sums(
            pix_m,
            radiance,
            bt_k,
            good,
            detectors,
            sat_m,
            los,
            window,
            table_of,
            tables,
            reach_rad,
            out,
        )
