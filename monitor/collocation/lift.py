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
+-:data:`REFERENCE_HALF_PX` pixels (~37 km; a 3 x 3 mean first, so that one noisy pixel does not set it).
The reach is set by the decks, not by the cone: a deck's middle beyond the reach of clear sky would be its
own reference and stand too low (docs/science.md, "Clouds with height").
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
from scipy.ndimage import maximum_filter, uniform_filter

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
        BT, K, shape (rows, cols); NaN where no usable pixel is within reach.
    """
    ok = good & np.isfinite(bt_k)
    filled = np.where(ok, bt_k, 0.0).astype(np.float32)
    count = uniform_filter(ok.astype(np.float32), 3, mode="nearest")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0.5, uniform_filter(filled, 3, mode="nearest") / count, -np.inf)
    ref = maximum_filter(mean, size=2 * half_px + 1, mode="nearest")
    return np.where(np.isfinite(ref), ref, np.nan).astype(np.float32)


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
        Heights, m, shape (rows, cols); 0 where not *good*.
    """
    cooling = np.nan_to_num(reference_k - bt_k, nan=0.0)
    return np.where(good, m_per_k * np.maximum(cooling, 0.0), 0.0).astype(np.float32)


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
        Which pixels of the scan to write, shape (32, cols).
    row0 : int
        The scan's first row.
    sat : numpy.ndarray
        The spacecraft's ECEF position at the scan's middle, m, shape (3,).
    vel : numpy.ndarray
        Its ECEF velocity, m/s, shape (3,).
    point : numpy.ndarray
        Written: per pixel the GEO point (ECEF, m), the ellipsoid's normal there and the scan angle (rad) seen
        from the spacecraft, shape (32, cols, 7).

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
