"""How high VIIRS pixels stand: the height of what each sees, from its BT (the parallax of high clouds).

GEO puts every VIIRS pixel where its line of sight meets the terrain. A cloud top H above it is seen along
the same line. CrIS sees the same cloud from another angle: its rows ahead (FOVs 7-9) look 19.1 mrad
forward, its rows behind 19.1 mrad back, VIIRS within 7 mrad of the scan plane. Seen from CrIS, the GEO
point and the cloud differ by ~23 urad per km of height for an outer row at nadir.
:mod:`monitor.collocation.render` draws from these heights what each CrIS FOV row sees.

How high. A cloud's top is colder than the clear surface around it by about its height times the lapse rate
(times the window channel's transmittance, which shrinks BT contrasts). Each pixel stands

    H = kappa * max(T_ref - BT, 0)

above its GEO point, where T_ref is the neighbourhood's clear-sky reference: the warmest BT within
+-:data:`REFERENCE_HALF_PX` I-band pixels (~37 km; half as many M-band pixels; a 3 x 3 mean first, so that one
noisy pixel does not set it). The reach is set by the decks, not by the cone: a deck's middle beyond the reach
of clear sky would be its own reference and stand too low (docs/science.md, "Clouds with height").
kappa (m per K) is not assumed: the assessment collocates at kappa = 0 and at :data:`PROBE_M_PER_K`, and
chooses the day's kappa from its own cost (:mod:`monitor.estimation.parallax`).

Where the pixel's line of sight comes from (:func:`scan_points`). The spacecraft position of each scan
(GEO's SCPosition, at the scan's middle) moves ~2 km over the Earth view, which would turn the line by ~1
mrad at the swath's edge; each pixel's own position is the scan's plus the velocity times its time from
the middle, which is its scan angle over VIIRS's rotation rate (one turn per scan period).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from monitor.collocation.geodesy import ecef_m
from monitor.core.constants import VIIRS_SCAN_US

REFERENCE_HALF_PX = 100  # +-100 pixels: ~37 km at nadir, the clear sky beside a deck tens of km wide
# The rendered collocation's lift, above the laws of real tops (159-239 m/K for tops at 7.8-5.2 K/km in
# band BT): the day's lift is sought on a straight line between no lift and this rendering, and a straight
# line reads a lift beyond its probe short.
PROBE_M_PER_K = 260.0
ROTATION_RAD_S = 2.0 * math.pi / (VIIRS_SCAN_US * 1e-6)


def reference_k(bt_k: np.ndarray, good: np.ndarray, half_px: int = REFERENCE_HALF_PX) -> np.ndarray:
    """The clear-sky reference BT around each pixel: the warmest 3 x 3 mean within +-*half_px* pixels.

    A 3 x 3 mean counts the usable pixels among the nine (the edge pixel standing in for those beyond the
    array) and is kept where at least five are; the warmest is taken over a square, a row pass and a
    column pass (van Herk 1992; Gil and Werman 1993: three comparisons a pixel, whatever the reach).

    Parameters
    ----------
    bt_k : numpy.ndarray
        The pixels' I5 BT, K, shape (rows, cols).
    good : numpy.ndarray
        Where a pixel is usable; the others never set the reference.
    half_px : int, optional
        The reach, pixels each side.

    Returns
    -------
    numpy.ndarray
        BT, K, float32, shape (rows, cols); NaN where no usable pixel is within reach.
    """
    bt = np.asarray(bt_k, np.float32)
    ok = np.asarray(good, np.bool_)
    out = np.empty(bt.shape, np.float32)
    if bt.size:
        _warmest_mean(bt, ok, int(half_px), out)
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _warmest_mean(bt: np.ndarray, good: np.ndarray, half: int, out: np.ndarray) -> None:
    """Fill *out* with :func:`reference_k`: the 3 x 3 means (a row pass of sums, then a column pass), then
    the warmest within +-*half* along each row and then along each column."""
    rows, cols = bt.shape
    row_sum = np.empty((rows, cols), np.float32)
    row_n = np.empty((rows, cols), np.int8)
    for i in range(rows):
        for j in range(cols):
            s, n = 0.0, 0
            for k in (max(j - 1, 0), j, min(j + 1, cols - 1)):  # the edge pixel repeated
                v = bt[i, k]
                if good[i, k] and math.isfinite(v):
                    s += v
                    n += 1
            row_sum[i, j], row_n[i, j] = s, n
    mean = np.empty((rows, cols), np.float32)
    for i in range(rows):
        above, below = max(i - 1, 0), min(i + 1, rows - 1)
        for j in range(cols):
            n = np.int64(row_n[above, j]) + row_n[i, j] + row_n[below, j]
            s = np.float64(row_sum[above, j]) + row_sum[i, j] + row_sum[below, j]
            mean[i, j] = s / n if n >= 5 else -np.inf  # more than half of the nine
    along = np.empty((rows, cols), np.float32)
    for i in range(rows):
        running_max(mean[i], half, along[i])
    _running_max_down(along, half, mean)  # the rows' maxima, now down the columns, into the means' place
    for i in range(rows):
        for j in range(cols):
            out[i, j] = mean[i, j] if mean[i, j] > -np.inf else np.nan


@numba.njit(cache=True, nogil=True, error_model="numpy")
def running_max(line: np.ndarray, half: int, out: np.ndarray) -> None:
    """The largest of *line* within +-*half* of each place (the window cut at the ends).

    Blocks of 2 half + 1, each with its running maximum from its start and from its end; a whole window is
    the end of one block and the start of the next, or one block (van Herk 1992; Gil and Werman 1993).

    Parameters
    ----------
    line : numpy.ndarray
        The values, shape (n,).
    half : int
        The window's reach each side, places.
    out : numpy.ndarray
        Written: the maxima, shape (n,).
    """
    n = line.shape[0]
    width = 2 * half + 1
    ahead = np.empty(n, line.dtype)
    behind = np.empty(n, line.dtype)
    for start in range(0, n, width):
        stop = min(start + width, n)
        ahead[start] = line[start]
        for i in range(start + 1, stop):
            ahead[i] = max(ahead[i - 1], line[i])
        behind[stop - 1] = line[stop - 1]
        for i in range(stop - 2, start - 1, -1):
            behind[i] = max(behind[i + 1], line[i])
    for i in range(n):
        lo, hi = i - half, i + half
        if lo <= 0:  # cut at the start: the first block's start part
            out[i] = ahead[min(hi, n - 1)]
        elif hi >= n - 1 and lo // width == (n - 1) // width:  # cut at the end, within the last block
            out[i] = behind[lo]
        else:
            out[i] = max(behind[lo], ahead[min(hi, n - 1)])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _running_max_down(grid: np.ndarray, half: int, out: np.ndarray) -> None:
    """:func:`running_max` down each column of *grid*, a row at a time (the rows are contiguous)."""
    rows, cols = grid.shape
    width = 2 * half + 1
    ahead = np.empty((rows, cols), grid.dtype)
    behind = np.empty((rows, cols), grid.dtype)
    for start in range(0, rows, width):
        stop = min(start + width, rows)
        ahead[start] = grid[start]
        for i in range(start + 1, stop):
            for j in range(cols):
                ahead[i, j] = max(ahead[i - 1, j], grid[i, j])
        behind[stop - 1] = grid[stop - 1]
        for i in range(stop - 2, start - 1, -1):
            for j in range(cols):
                behind[i, j] = max(behind[i + 1, j], grid[i, j])
    for i in range(rows):
        lo, hi = i - half, min(i + half, rows - 1)
        if lo <= 0:
            out[i] = ahead[hi]
        elif hi == rows - 1 and lo // width == (rows - 1) // width:
            out[i] = behind[lo]
        else:
            for j in range(cols):
                out[i, j] = max(behind[lo, j], ahead[hi, j])


def height_above_m(bt_k: np.ndarray, good: np.ndarray, reference_k: np.ndarray, m_per_k: float) -> np.ndarray:
    """Each pixel's height above its GEO point: *m_per_k* times how much colder than its clear sky it is.

    Parameters
    ----------
    bt_k : numpy.ndarray
        The pixels' I5 BT, K, shape (rows, cols).
    good : numpy.ndarray
        Where a pixel is usable.
    reference_k : numpy.ndarray
        The clear-sky reference BT (:func:`reference_k`), K.
    m_per_k : float
        The lift, m per K of BT below the reference.

    Returns
    -------
    numpy.ndarray
        Heights, m, float32, shape (rows, cols); 0 where not *good* or the reference is NaN.
    """
    out = np.empty(np.shape(bt_k), np.float32)
    _heights(
        np.asarray(bt_k, np.float32), np.asarray(good, np.bool_), np.asarray(reference_k, np.float32),
        float(m_per_k), out,
    )  # fmt: skip
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _heights(bt: np.ndarray, good: np.ndarray, ref: np.ndarray, m_per_k: float, out: np.ndarray) -> None:
    """Fill *out* with :func:`height_above_m`."""
    for i in range(bt.shape[0]):
        for j in range(bt.shape[1]):
            cooling = ref[i, j] - bt[i, j]
            ok = good[i, j] and math.isfinite(cooling)
            out[i, j] = m_per_k * max(cooling, 0.0) if ok else 0.0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def scan_points(
    lat: np.ndarray,
    lon: np.ndarray,
    h: np.ndarray,
    mask: np.ndarray,
    row0: int,
    sat: np.ndarray,
    vel: np.ndarray,
    point: np.ndarray,
) -> float:
    """The GEO points, ellipsoid normals and scan angles of one scan's pixels, for the rendering.

    A pixel is seen from the spacecraft at the scan's middle plus the velocity times order x angle /
    :data:`ROTATION_RAD_S`.

    Parameters
    ----------
    lat, lon, h : numpy.ndarray
        The granule's GEO: latitude and longitude (rad), height (m), shape (rows, cols).
    mask : numpy.ndarray
        Which pixels of the scan to write, shape (detectors, cols).
    row0 : int
        The scan's first row.
    sat : numpy.ndarray
        The spacecraft's ECEF position at the scan's middle, m, shape (3,).
    vel : numpy.ndarray
        Its ECEF velocity, m/s, shape (3,).
    point : numpy.ndarray
        Written: per pixel the GEO point (ECEF, m), the ellipsoid's normal there and the scan angle (rad) seen
        from the spacecraft, shape (detectors, cols, 7).

    Returns
    -------
    float
        1 when the columns come in time order with the scan angle, -1 against it (the sign of the
        least-squares slope of the angle over the column; 1 where all lie in one column or it is flat), 0 when
        no pixel is masked.
    """
    sx, sy, sz = sat[0], sat[1], sat[2]
    vx, vy, vz = vel[0], vel[1], vel[2]
    norm = math.sqrt(sx * sx + sy * sy + sz * sz)
    nx, ny, nz = -sx / norm, -sy / norm, -sz / norm  # nadir
    ax, ay, az = vy * sz - vz * sy, vz * sx - vx * sz, vx * sy - vy * sx  # velocity x position
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    ax, ay, az = ax / norm, ay / norm, az / norm
    count, sum_c, sum_a, sum_ca = 0, 0.0, 0.0, 0.0
    first, last = mask.shape[1], -1
    for i in range(mask.shape[0]):
        for c in range(mask.shape[1]):
            if mask[i, c]:
                la, lo, hh = lat[row0 + i, c], lon[row0 + i, c], h[row0 + i, c]
                px, py, pz = ecef_m(la, lo, hh)
                cos_la = math.cos(la)
                lx, ly, lz = px - sx, py - sy, pz - sz
                angle = math.atan2(lx * ax + ly * ay + lz * az, lx * nx + ly * ny + lz * nz)
                q = point[i, c]
                q[0], q[1], q[2], q[6] = px, py, pz, angle
                q[3], q[4], q[5] = cos_la * math.cos(lo), cos_la * math.sin(lo), math.sin(la)
                count += 1
                sum_c += c
                sum_a += angle
                sum_ca += c * angle
                first, last = min(first, c), max(last, c)
    if count == 0:
        return 0.0
    if last > first:
        slope = count * sum_ca - sum_c * sum_a
        return -1.0 if slope < 0 else 1.0
    return 1.0
