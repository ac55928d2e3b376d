"""Where the rays to each VIIRS GEO point lie: the along-track coordinate, and the in-track (and, for a
rendering that needs them, cross-track) tangents of VIIRS's ray and of each CrIS FOV row's ray.

The rendering (:mod:`monitor.collocation.render`) sweeps each CrIS ray down a VIIRS column's slanted plane.
A CrIS row at in-track SBF angle alpha (19.1 mrad ahead or behind for the outer rows, Wang et al. 2017
section 2.1) sees a GEO point from where the spacecraft is when the point lies at alpha in its SBF, seconds
before or after VIIRS saw it: its ray differs from VIIRS's in-track by about alpha (1 + range / R_earth),
and across the track by the little the Earth turns under the track meanwhile.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from monitor.collocation.lift import ROTATION_RAD_S, scan_points
from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.constants import VIIRS_DETECTORS

# a CrIS view's tangent is traced every this many columns and between them interpolated in scan angle
# (it varies smoothly along a scan)
TANGENT_STEP = 16


def view_tangents(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
    first_column: int = 0,
    detectors: int = VIIRS_DETECTORS,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The along-track coordinate and in-track tangents of the VIIRS and CrIS rays to each pixel's GEO point.

    The SBF during a scan is VIIRS's: it scans the SBF's y-z plane; the columns run along its x axis on the
    ground. VIIRS sees the pixel from the spacecraft at the pixel's time
    (:func:`monitor.collocation.lift.scan_points`). CrIS at angle alpha sees it from the point S' of the track
    where (P - S') . x_sbf = tan(alpha) (P - S') . z_sbf, the SBF taken at S'. A difference of in-track angles
    between the two instruments is about 1 + range / R_earth times larger at the ground (the local vertical
    turns along the track too): 21.6 mrad for an outer row at nadir. The CrIS tangent is traced at every
    :data:`TANGENT_STEP`-th column and at each run's ends, and linearly in scan angle between them, where it
    varies smoothly.

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    good : numpy.ndarray
        Where a pixel is usable.
    sat_m, velocity_m_s : numpy.ndarray
        Each scan's spacecraft position (m) and velocity (m/s) at its middle, ECEF, shape (nscan, 3).
    cris_alpha_rad : numpy.ndarray
        The CrIS views' in-track angles in the spacecraft body frame, rad, positive ahead.
    first_column : int
        The granule column of the first column given, so that a part is traced as in the whole.
    detectors : int, optional
        The rows of a scan (the grid's detectors: :data:`monitor.core.bands.GRIDS`).

    Returns
    -------
    x_m : numpy.ndarray
        Each GEO point's coordinate along the track, m, along the first scan's SBF x axis; NaN where
        unusable; shape (rows, cols).
    viirs_tan : numpy.ndarray
        The in-track tangent of each pixel's VIIRS ray, shape (rows, cols).
    cris_tan : numpy.ndarray
        Per view, the in-track tangent of the CrIS ray to each GEO point: the horizontal run along the
        column per unit of height towards the spacecraft, positive along +x; shape (views, rows, cols).
    """
    x, b, a, _ = _traced(
        lat_rad, lon_rad, height_m, good, sat_m, velocity_m_s, cris_alpha_rad, first_column, False, detectors
    )
    return x, b, a


@dataclass(frozen=True)
class Across:
    """Where a granule's rays lie across the track: what lets a ray take its value at its own cross-track
    position (:func:`view_tangents_across`).

    Attributes
    ----------
    geo_m : numpy.ndarray
        Each pixel's GEO point, ECEF, m, shape (rows, cols, 3); NaN where unusable.
    unit : numpy.ndarray
        The horizontal unit vector across the track at each GEO point (the local vertical cross the
        column's way), ECEF, shape (rows, cols, 3).
    viirs_tan : numpy.ndarray
        The cross-track tangent of each pixel's VIIRS ray: its run along *unit* per metre of height towards
        the spacecraft, shape (rows, cols).
    cris_tan : numpy.ndarray
        Per view, the same of the CrIS ray to each GEO point, shape (views, rows, cols).
    """

    geo_m: np.ndarray
    unit: np.ndarray
    viirs_tan: np.ndarray
    cris_tan: np.ndarray


def view_tangents_across(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
    first_column: int = 0,
    detectors: int = VIIRS_DETECTORS,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, Across]:
    """:func:`view_tangents`, and where the rays lie across the track.

    A CrIS ray meets a GEO point from where the spacecraft is seconds before or after VIIRS saw it, and
    the Earth has turned under the track meanwhile, so at a height it lies a little across the track from
    VIIRS's ray to the same point; pixels of other scans and detectors at one column index lie across
    the track from it too (the Earth's turn between scans, the bow-tie's smile).

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    good : numpy.ndarray
        Where a pixel is usable.
    sat_m, velocity_m_s : numpy.ndarray
        Each scan's spacecraft position (m) and velocity (m/s) at its middle, ECEF, shape (nscan, 3).
    cris_alpha_rad : numpy.ndarray
        The CrIS views' in-track angles in the spacecraft body frame, rad, positive ahead.
    first_column : int
        The granule column of the first column given, so that a part is traced as in the whole.
    detectors : int, optional
        The rows of a scan (the grid's detectors: :data:`monitor.core.bands.GRIDS`).

    Returns
    -------
    x_m, viirs_tan, cris_tan : numpy.ndarray
        As :func:`view_tangents`.
    across : Across
        The GEO points, the across-track directions and both instruments' cross-track tangents; the CrIS
        tangent traced and interpolated as the in-track one.
    """
    x, b, a, across = _traced(
        lat_rad, lon_rad, height_m, good, sat_m, velocity_m_s, cris_alpha_rad, first_column, True, detectors
    )
    assert across is not None
    return x, b, a, across


def _traced(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
    first_column: int,
    with_across: bool,
    detectors: int,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, Across | None]:
    """:func:`_tangents` into new arrays (NaN where no tangent is traced); the :class:`Across` with
    *with_across*."""
    rows, cols = np.shape(lat_rad)
    views = len(cris_alpha_rad)
    sat = np.ascontiguousarray(sat_m, np.float64)
    vel = np.ascontiguousarray(velocity_m_s, np.float64)
    # the kernel writes every element (NaN where it traces none), each scan on the thread that traces it
    x = np.empty((rows, cols))
    b = np.empty((rows, cols), np.float32)
    a = np.empty((views, rows, cols), np.float32)
    n = rows if with_across else 0
    across = Across(
        np.empty((n, cols, 3)),
        np.empty((n, cols, 3)),
        np.empty((n, cols), np.float32),
        np.empty((views, n, cols), np.float32),
    )
    geo = [np.ascontiguousarray(v, np.float64) for v in (lat_rad, lon_rad, height_m)]
    tan_alpha = np.tan(np.asarray(cris_alpha_rad, np.float64))
    with KERNEL_LOCK:
        _tangents(
            *geo, np.ascontiguousarray(good, np.bool_), sat, vel, tan_alpha, first_column, detectors, x, b, a,
            across.geo_m, across.unit, across.viirs_tan, across.cris_tan,
        )  # fmt: skip
    return x, b, a, across if with_across else None


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _scan_normal(
    point: np.ndarray, good: np.ndarray, s: np.ndarray, v: np.ndarray, order: float
) -> np.ndarray:
    """The SBF's x axis during one scan: the normal of the plane VIIRS's two centre detectors (15 and 16 of
    the I grid's 32, 7 and 8 of the M grid's 16) sweep, from their lines of sight at the scan's two farthest
    columns (the spacecraft at each pixel's time), turned towards the velocity. VIIRS scans the SBF's y-z
    plane; the SBF is yawed against the ECEF velocity (~3.5 degrees at the equator), which at a 50 degree
    scan angle is ~70 mrad in-track. NaN when no column holds both."""
    out = np.full(3, np.nan)
    lo, hi = good.shape[0] // 2 - 1, good.shape[0] // 2
    first, last = -1, -1
    for c in range(good.shape[1]):
        if good[lo, c] and good[hi, c]:
            last = c
            if first < 0:
                first = c
    if first < 0 or last == first:
        return out
    rays = np.empty((2, 3))
    for n, c in enumerate((first, last)):
        ray = np.zeros(3)
        for i in (lo, hi):
            q = point[i, c]
            d = q[:3] - (s + v * (order * q[6] / ROTATION_RAD_S))
            ray += d / math.sqrt(d @ d)
        rays[n] = ray
    normal = np.cross(rays[0], rays[1])
    normal /= math.sqrt(normal @ normal)
    return normal if normal @ v > 0 else -normal


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _tangents(
    lat: np.ndarray,
    lon: np.ndarray,
    h: np.ndarray,
    good: np.ndarray,
    sat: np.ndarray,
    vel: np.ndarray,
    tan_alpha: np.ndarray,
    first_column: int,
    det: int,
    x: np.ndarray,
    b: np.ndarray,
    a: np.ndarray,
    geo: np.ndarray,
    across: np.ndarray,
    b_across: np.ndarray,
    a_across: np.ndarray,
) -> None:
    """Fill *x*, *b* and *a* (:func:`view_tangents`), one scan a task; x along the first scan's
    SBF x. When *geo* has rows, also *geo*, *across*, *b_across* and *a_across*
    (:func:`view_tangents_across`). Every element is written: NaN where no tangent is traced."""
    cols = lat.shape[1]
    with_across = geo.shape[0] > 0
    nscan = lat.shape[0] // det
    for k in numba.prange(nscan):  # NaN first, each scan by its own thread
        _unset(k * det, (k + 1) * det, x, b, a, geo, across, b_across, a_across)
    _unset(nscan * det, lat.shape[0], x, b, a, geo, across, b_across, a_across)  # a part scan
    axis0 = np.full(3, np.nan)
    for k in range(lat.shape[0] // det):  # the first scan with an SBF: x's axis
        if np.all(np.isfinite(sat[k])) and np.all(np.isfinite(vel[k])):
            point = np.empty((det, cols, 7))
            rows = good[k * det : (k + 1) * det]
            order = scan_points(lat, lon, h, rows, k * det, sat[k], vel[k], point)
            if order != 0.0:
                axis0 = _scan_normal(point, rows, sat[k], vel[k], order)
                if np.all(np.isfinite(axis0)):
                    break
    if not np.all(np.isfinite(axis0)):
        return
    for k in numba.prange(lat.shape[0] // det):
        if not (np.all(np.isfinite(sat[k])) and np.all(np.isfinite(vel[k]))):
            continue
        row0 = k * det
        rows = good[row0 : row0 + det]
        point = np.empty((det, cols, 7))
        order = scan_points(lat, lon, h, rows, row0, sat[k], vel[k], point)
        if order == 0.0:
            continue
        s = sat[k]
        v = vel[k]
        xs = _scan_normal(point, rows, s, v, order)
        if not np.all(np.isfinite(xs)):
            continue
        # scalars, not 3-vectors: a small array made per pixel and view is a heap allocation each
        xs0, xs1, xs2 = xs[0], xs[1], xs[2]
        s0, s1, s2 = s[0], s[1], s[2]
        v0, v1, v2 = v[0], v[1], v[2]
        for i in range(det):
            last = -1  # the last column of this detector with a tangent of its own
            for c in range(cols):
                if not rows[i, c]:
                    continue
                q = point[i, c]
                p0, p1, p2, u0, u1, u2 = q[0], q[1], q[2], q[3], q[4], q[5]
                # the SBF's x on the horizontal at the point: a column's way
                xu = xs0 * u0 + xs1 * u1 + xs2 * u2
                t0, t1, t2 = xs0 - xu * u0, xs1 - xu * u1, xs2 - xu * u2
                norm = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
                t0, t1, t2 = t0 / norm, t1 / norm, t2 / norm
                w0, w1, w2 = u1 * t2 - u2 * t1, u2 * t0 - u0 * t2, u0 * t1 - u1 * t0  # across: u x t
                x[row0 + i, c] = p0 * axis0[0] + p1 * axis0[1] + p2 * axis0[2]
                when = order * q[6] / ROTATION_RAD_S
                d0, d1, d2 = s0 + v0 * when - p0, s1 + v1 * when - p1, s2 + v2 * when - p2  # to VIIRS then
                d_up = d0 * u0 + d1 * u1 + d2 * u2
                b[row0 + i, c] = (d0 * t0 + d1 * t1 + d2 * t2) / d_up
                if with_across:
                    geo[row0 + i, c, 0], geo[row0 + i, c, 1], geo[row0 + i, c, 2] = p0, p1, p2
                    across[row0 + i, c, 0], across[row0 + i, c, 1], across[row0 + i, c, 2] = w0, w1, w2
                    b_across[row0 + i, c] = (d0 * w0 + d1 * w1 + d2 * w2) / d_up
                ends = last < 0 or c == cols - 1 or not rows[i, c + 1]  # a run of usable pixels
                node = ends or (first_column + c) % TANGENT_STEP == 0
                if not node:
                    continue
                for j in range(tan_alpha.shape[0]):
                    a_in, a_out = _cris_tangent(p0, p1, p2, d0, d1, d2, t0, t1, t2, u0, u1, u2, xs0, xs1,
                                                xs2, v0, v1, v2, tan_alpha[j], w0, w1, w2)  # fmt: skip
                    a[j, row0 + i, c] = a_in
                    if with_across:
                        a_across[j, row0 + i, c] = a_out
                # the columns since the last node, linearly in scan angle between the two
                if last >= 0 and c - last > 1:
                    angle0 = point[i, last, 6]
                    span = q[6] - angle0
                    for m in range(last + 1, c):
                        if rows[i, m]:
                            w = (point[i, m, 6] - angle0) / span if span != 0.0 else 0.0
                            for j in range(tan_alpha.shape[0]):
                                a[j, row0 + i, m] = (1.0 - w) * a[j, row0 + i, last] + w * a[j, row0 + i, c]
                                if with_across:
                                    a_across[j, row0 + i, m] = (1.0 - w) * a_across[j, row0 + i, last] + (
                                        w * a_across[j, row0 + i, c]
                                    )
                last = c


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _unset(
    row0: int,
    row1: int,
    x: np.ndarray,
    b: np.ndarray,
    a: np.ndarray,
    geo: np.ndarray,
    across: np.ndarray,
    b_across: np.ndarray,
    a_across: np.ndarray,
) -> None:
    """NaN in every output of :func:`_tangents` in rows *row0* to *row1* (excluded)."""
    rows = slice(row0, row1)
    x[rows] = np.nan
    b[rows] = np.nan
    a[:, rows] = np.nan
    if geo.shape[0] > 0:
        geo[rows] = np.nan
        across[rows] = np.nan
        b_across[rows] = np.nan
        a_across[:, rows] = np.nan


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _cris_tangent(
    p0: float, p1: float, p2: float, d0: float, d1: float, d2: float, t0: float, t1: float, t2: float,
    u0: float, u1: float, u2: float, xs0: float, xs1: float, xs2: float, v0: float, v1: float, v2: float,
    tan_alpha: float, w0: float, w1: float, w2: float,
) -> tuple[float, float]:  # fmt: skip
    """The in-track tangent a of the CrIS ray at SBF angle tan(alpha) to the GEO point p (m, ECEF; its
    local vertical u, the column's way t on the horizontal; d from p to VIIRS at the pixel's time; xs the
    scan's SBF x; v the velocity): :func:`view_tangents`; and its tangent along the horizontal across the
    track w (:func:`view_tangents_across`)."""
    r0, r1, r2 = d0, d1, d2
    for _ in range(3):  # the SBF turns with the spacecraft's move: 11 % of it, then 1 %
        z0, z1, z2 = p0 + r0, p1 + r1, p2 + r2
        norm = -math.sqrt(z0 * z0 + z1 * z1 + z2 * z2)
        z0, z1, z2 = z0 / norm, z1 / norm, z2 / norm
        xz = xs0 * z0 + xs1 * z1 + xs2 * z2
        x0, x1, x2 = xs0 - xz * z0, xs1 - xz * z1, xs2 - xz * z2
        norm = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        x0, x1, x2 = x0 / norm, x1 / norm, x2 / norm
        zx = z0 * x0 + z1 * x1 + z2 * x2
        z0, z1, z2 = z0 - zx * x0, z1 - zx * x1, z2 - zx * x2
        norm = math.sqrt(z0 * z0 + z1 * z1 + z2 * z2)
        z0, z1, z2 = z0 / norm, z1 / norm, z2 / norm
        # along the track by dt: (P - S') . x = tan(alpha) (P - S') . z
        rx, rz = r0 * x0 + r1 * x1 + r2 * x2, r0 * z0 + r1 * z1 + r2 * z2
        vx, vz = v0 * x0 + v1 * x1 + v2 * x2, v0 * z0 + v1 * z1 + v2 * z2
        dt = (-rx + tan_alpha * rz) / (vx - tan_alpha * vz)
        r0, r1, r2 = r0 + dt * v0, r1 + dt * v1, r2 + dt * v2
    up = r0 * u0 + r1 * u1 + r2 * u2
    return (r0 * t0 + r1 * t1 + r2 * t2) / up, (r0 * w0 + r1 * w1 + r2 * w2) / up
