"""VIIRS pixels placed at the height of what they see: the parallax of clouds with height.

GEO puts every VIIRS pixel where its line of sight meets the terrain. A cloud top H above it is seen along
the same line, so the point VIIRS saw is the GEO point moved back up its line of sight by H / cos(z) (z the
view zenith angle there). CrIS sees the same cloud from another angle: its rows ahead (FOVs 7-9) look
19.1 mrad forward, its rows behind 19.1 mrad back, VIIRS within 7 mrad of the scan plane. Seen from CrIS,
the GEO point and the cloud differ by ~23 urad per km of height for an outer row at nadir. With every pixel
at its 3-D point, each CrIS cone meets the scene where it is, whatever angle it looks from
(:mod:`monitor.collocation.collocate` tests angles from the CrIS spacecraft to 3-D points).

How high. A cloud's top is colder than the clear surface around it by about its height times the lapse rate
(times the window channel's transmittance, which shrinks BT contrasts). Each pixel is lifted by

    H = kappa * max(T_ref - BT, 0),

where T_ref is the neighbourhood's clear-sky reference: the warmest BT within +-:data:`REFERENCE_HALF_PX`
pixels (~15 km; a 3 x 3 mean first, so that one noisy pixel does not set it). kappa (m per K) is not
assumed: the assessment collocates at kappa = 0 and at :data:`PROBE_M_PER_K`, and chooses the day's kappa
from its own cost (:mod:`monitor.estimation.parallax`).

Where the pixel's line of sight comes from. The spacecraft position of each scan (GEO's SCPosition, at the
scan's middle) moves ~2 km over the Earth view, which would turn the line by ~1 mrad at the swath's edge;
each pixel's own position is the scan's plus the velocity times its time from the middle, which is its scan
angle over VIIRS's rotation rate (one turn per scan period).
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy.ndimage import maximum_filter, uniform_filter

from monitor.collocation.geodesy import ecef_m, geodetic_rad_m
from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.constants import VIIRS_DETECTORS, VIIRS_SCAN_US

REFERENCE_HALF_PX = 40  # +-40 pixels: ~15 km at nadir, wider than a CrIS cone's reach from its edge
PROBE_M_PER_K = 180.0  # the second collocation's lift: 6.5 K/km seen through a window transmittance ~0.85
ROTATION_RAD_S = 2.0 * math.pi / (VIIRS_SCAN_US * 1e-6)


def reference_k(bt_k: np.ndarray, good: np.ndarray) -> np.ndarray:
    """The clear-sky reference BT (K) around each pixel of *bt_k* (rows, cols): the warmest 3 x 3 mean
    within +-REFERENCE_HALF_PX pixels (unusable pixels never set it; NaN where none is usable)."""
    ok = good & np.isfinite(bt_k)
    filled = np.where(ok, bt_k, 0.0).astype(np.float32)
    count = uniform_filter(ok.astype(np.float32), 3, mode="nearest")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0.5, uniform_filter(filled, 3, mode="nearest") / count, -np.inf)
    ref = maximum_filter(mean, size=2 * REFERENCE_HALF_PX + 1, mode="nearest")
    return np.where(np.isfinite(ref), ref, np.nan).astype(np.float32)


def lift_m(bt_k: np.ndarray, good: np.ndarray, m_per_k: float) -> np.ndarray:
    """Each pixel's height (m) above its GEO point: *m_per_k* times how much colder than the clear-sky
    reference it is (0 where unusable)."""
    if m_per_k == 0.0:
        return np.zeros(bt_k.shape, np.float32)
    return height_above_m(bt_k, good, reference_k(bt_k, good), m_per_k)


def height_above_m(bt_k: np.ndarray, good: np.ndarray, reference_k: np.ndarray, m_per_k: float) -> np.ndarray:
    """Each pixel's height (m) above its GEO point given its clear-sky *reference_k* (:func:`lift_m`)."""
    cooling = np.nan_to_num(reference_k - bt_k, nan=0.0)
    return np.where(good, m_per_k * np.maximum(cooling, 0.0), 0.0).astype(np.float32)


def lifted(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    lift: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lat_rad, lon_rad, height_m) of the pixels (rows of 32-detector scans, cols) moved back up their
    lines of sight by *lift* (m, above the GEO point) / cos(view zenith), from the spacecraft at each
    pixel's time (scan *sat_m* and *velocity_m_s* (nscan, 3), ECEF, at the scan's middle). Computed in
    float64, returned in float32: the swath keeps its points in float32 (0.5 m), and a granule's three
    float64 copies would be 240 MB more at the collocation's peak. Compiled, in parallel over scans
    (:func:`_lift_scans`): every pixel colder than its reference is moved, ~10 million per granule."""
    lat, lon, h = (np.array(a, np.float32) for a in (lat_rad, lon_rad, height_m))
    inputs = [
        np.ascontiguousarray(a, t)
        for a, t in zip(
            (lat_rad, lon_rad, height_m, lift, sat_m, velocity_m_s),
            (np.float64, np.float64, np.float64, np.float32, np.float64, np.float64),
            strict=True,
        )
    ]
    with KERNEL_LOCK, numba.parallel_chunksize(1):  # a scan a task: their lifted pixels vary
        _lift_scans(*inputs, lat, lon, h)
    return lat, lon, h


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
    """For the pixels of the scan starting at row *row0* where *mask* (32, cols) holds, write into *point*
    (32, cols, 7) the GEO point in ECEF (m, :func:`monitor.collocation.geodesy.ecef_m`), the ellipsoid's
    normal there and the scan angle (rad) seen from the scan's spacecraft position *sat* (3,) with
    velocity *vel*; return whether the columns come in time order with the scan angle (1) or against it
    (-1: the sign of the least-squares slope of the angle over the column; 1 where all lie in one column
    or it is flat), 0 when no pixel is masked. A pixel is seen from the spacecraft at the scan's middle
    plus the velocity times order x angle / ROTATION_RAD_S."""
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


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _lift_scans(
    lat: np.ndarray,
    lon: np.ndarray,
    h: np.ndarray,
    lift: np.ndarray,
    sat: np.ndarray,
    vel: np.ndarray,
    out_lat: np.ndarray,
    out_lon: np.ndarray,
    out_h: np.ndarray,
) -> None:
    """Write into *out_** the lifted pixels (lift > 0) of every scan whose spacecraft position is known
    (:func:`lifted`). Per scan, two passes over its lifted pixels: the first places each GEO point and
    reads its scan angle and the columns' time order (:func:`scan_points`); the second moves each point,
    the spacecraft taken at the pixel's time: the scan's middle plus its scan angle over the rotation
    rate."""
    cols = lat.shape[1]
    for k in numba.prange(lat.shape[0] // VIIRS_DETECTORS):
        sx, sy, sz = sat[k, 0], sat[k, 1], sat[k, 2]
        if not (math.isfinite(sx) and math.isfinite(sy) and math.isfinite(sz)):
            continue
        vx, vy, vz = vel[k, 0], vel[k, 1], vel[k, 2]
        row0 = k * VIIRS_DETECTORS
        point = np.empty((VIIRS_DETECTORS, cols, 7))  # ECEF (m), the normal, the scan angle (rad)
        order = scan_points(lat, lon, h, lift[row0 : row0 + VIIRS_DETECTORS] > 0, row0, sat[k], vel[k], point)
        if order == 0.0:
            continue
        for i in range(VIIRS_DETECTORS):
            for c in range(cols):
                if lift[row0 + i, c] > 0:
                    q = point[i, c]
                    t = order * q[6] / ROTATION_RAD_S
                    wx, wy, wz = (
                        sx + vx * t - q[0],
                        sy + vy * t - q[1],
                        sz + vz * t - q[2],
                    )  # to the spacecraft
                    norm = math.sqrt(wx * wx + wy * wy + wz * wz)
                    wx, wy, wz = wx / norm, wy / norm, wz / norm
                    d = lift[row0 + i, c] / (
                        wx * q[3] + wy * q[4] + wz * q[5]
                    )  # along the view: lift / cos(zen)
                    x, y, z = geodetic_rad_m(q[0] + d * wx, q[1] + d * wy, q[2] + d * wz)
                    out_lat[row0 + i, c], out_lon[row0 + i, c], out_h[row0 + i, c] = x, y, z
