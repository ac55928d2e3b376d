"""What a CrIS FOV row sees of a VIIRS column whose pixels stand at a height: hidden ground out, walls in.

The point lift (:mod:`monitor.collocation.lift`) moves each pixel up its VIIRS line of sight to the height
its BT implies and lets the cone test look at the lifted points from CrIS. From an outer FOV row's slant
view that still counts ground a lifted cloud hides, and misses the cloud's side (its wall) that the view
meets (docs/science.md, "Clouds have height"). This module renders instead, along one VIIRS column (the
pixels of one scan angle, sorted along the track): what the ray of a CrIS FOV row that meets the ground at
each pixel's GEO point meets first. The cone test can then keep every pixel at its GEO point and give it
the radiance the FOV row sees there: the rays through a ground patch are the rays the patch's solid angle
holds, so hidden ground drops out and walls come in by themselves.

**The geometry, in one column's vertical plane along the track** (x along the track, m; z up, m; the
cross-track component is the same for both instruments, which look from one spacecraft at one scan
angle). Pixel j's GEO point is x_j; VIIRS saw it along the ray x = x_j + z b_j (b_j the in-track tangent
of its view from the vertical, towards the spacecraft). Standing at height h_j, its column occupies

    |x - T_j| <= w_j / 2,  0 <= z <= h_j,   T_j = x_j + h_j b_j,

(w_j its along-track width). The CrIS row's ray that meets the ground at x_i is x = x_i + z a_i. It is
inside column j horizontally for z in an interval [z_lo, z_hi] (all z when a_i = 0 and |x_i - T_j| <=
w_j / 2). Coming down from the spacecraft, it meets column j first at

    z*_j = min(h_j, z_hi)   if that is >= max(z_lo, 0):

its top when z*_j = h_j (the pixel's own BT), its side wall otherwise, at height z_hi, whose BT the height
law gives: the clear-sky reference minus z / kappa (kappa m per K,
:func:`monitor.collocation.lift.height_above_m`).
What the ray sees is the column with the highest z*: anything lower on the ray is hidden behind it. Ties
(flat ground, z* = 0) go to the column whose top centre is nearest the ray.

The assessment does not use this yet: its probe collocation still lifts each pixel to a point
(:mod:`monitor.collocation.lift`) until the day's lift learnt from rendered views is measured.

Only columns within the reach of the ray matter: |x_i - x_j| <= w_j / 2 + h_max (|a_i| + |b_j|), a few
pixels for clouds below 20 km and views within 0.05 of the vertical; the sweep looks no farther.
Compiled, in parallel over the columns.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from monitor.collocation.lift import ROTATION_RAD_S, height_above_m, reference_k, scan_points
from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.constants import VIIRS_DETECTORS

COLUMNS_PER_PASS = 512  # columns rendered at a time: the sort's and the tangents' arrays stay ~60 MB


def rendered_bt(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
    m_per_k: float,
) -> np.ndarray:
    """The BT (K, float32 (rows, cols) per CrIS FOV row: (len(cris_alpha_rad), rows, cols)) that each
    CrIS FOV row (in-track SBF angle *cris_alpha_rad*) sees along its ray to each GEO point of a VIIRS
    granule (rows of 32-detector scans, GEO (lat_rad, lon_rad, height_m), BT *bt_k*, usable where
    *good*; NaN elsewhere), each pixel standing *m_per_k* m per K colder than its clear-sky reference
    above its GEO point (:func:`monitor.collocation.lift.height_above_m`), and its sides at the
    reference minus their height over *m_per_k*: :func:`view_tangents`, then :func:`render_columns` on
    each column sorted along the track (the scans' bow-tie overlap interleaves their rows there). A
    pixel's along-track width is its column's median detector step."""
    rows, cols = np.shape(bt_k)
    out = np.full((len(cris_alpha_rad), rows, cols), np.nan, np.float32)
    usable = np.asarray(good, bool) & np.isfinite(bt_k)
    reference = reference_k(bt_k, usable)  # over the whole granule: it looks 40 pixels around
    height = height_above_m(bt_k, usable, reference, m_per_k)
    for c0 in range(0, cols, COLUMNS_PER_PASS):
        part = slice(c0, min(c0 + COLUMNS_PER_PASS, cols))
        ok = usable[:, part]
        bt = np.asarray(bt_k[:, part], np.float64)
        ref = reference[:, part]
        x, b, a = view_tangents(
            lat_rad[:, part], lon_rad[:, part], height_m[:, part], ok, sat_m, velocity_m_s, cris_alpha_rad
        )
        x = np.where(ok, x, np.nan)
        steps = np.abs(np.diff(x.reshape(rows // VIIRS_DETECTORS, VIIRS_DETECTORS, -1), axis=1))
        with np.errstate(all="ignore"):
            width = np.broadcast_to(np.nanmedian(steps, axis=(0, 1)), x.shape)
        order = np.argsort(np.where(np.isfinite(x), x, np.inf), axis=0, kind="stable")

        def along(v: np.ndarray, order: np.ndarray = order) -> np.ndarray:
            return np.take_along_axis(np.asarray(v, np.float64), order, axis=0)

        xs, ws, hs, bts, refs, bs = (along(v) for v in (x, width, height[:, part], bt, ref, b))
        for j in range(len(cris_alpha_rad)):
            seen, _ = render_columns(xs, ws, hs, bts, refs, bs, along(a[j]), m_per_k)
            unsorted = np.empty_like(seen)
            np.put_along_axis(unsorted, order, seen, axis=0)
            out[j, :, part] = np.where(ok, unsorted, np.nan)
    return out


def view_tangents(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per pixel of a VIIRS granule (rows of 32-detector scans; *good* where usable) the along-track
    coordinate x of its GEO point (m, along the first scan's SBF x axis; NaN where unusable), the in-track
    tangent b of its VIIRS ray, and per in-track SBF angle of *cris_alpha_rad* (rad, positive ahead) the
    in-track tangent a of a CrIS ray at that angle to the same GEO point: the horizontal run along the
    column per unit of height towards the spacecraft, positive along +x (:func:`render_columns`).

    The SBF during a scan is VIIRS's: it scans the SBF's y-z plane (:func:`_scan_normal`); the columns
    run along its x axis on the ground. VIIRS sees the pixel from the spacecraft at the pixel's time
    (scan *sat_m*, *velocity_m_s* (nscan, 3) ECEF at the scan's middle,
    :func:`monitor.collocation.lift.scan_points`).
    CrIS at angle alpha sees it from the point S' of the track where (P - S') . x_sbf =
    tan(alpha) (P - S') . z_sbf, the SBF taken at S' (three steps: its nadir turns by the move over
    R_earth + altitude). A difference of in-track angles between the two instruments is about
    1 + range / R_earth times larger at the ground (the local vertical turns along the track too): 21.6 mrad
    for an outer row at nadir."""
    rows, cols = np.shape(lat_rad)
    sat = np.ascontiguousarray(sat_m, np.float64)
    vel = np.ascontiguousarray(velocity_m_s, np.float64)
    x = np.full((rows, cols), np.nan)
    b = np.full((rows, cols), np.nan, np.float32)
    a = np.full((len(cris_alpha_rad), rows, cols), np.nan, np.float32)
    geo = [np.ascontiguousarray(v, np.float64) for v in (lat_rad, lon_rad, height_m)]
    tan_alpha = np.tan(np.asarray(cris_alpha_rad, np.float64))
    with KERNEL_LOCK:
        _tangents(*geo, np.ascontiguousarray(good, np.bool_), sat, vel, tan_alpha, x, b, a)
    return x, b, a


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _scan_normal(
    point: np.ndarray, good: np.ndarray, s: np.ndarray, v: np.ndarray, order: float
) -> np.ndarray:
    """The SBF's x axis during one scan: the normal of the plane VIIRS's centre detectors (15 and 16)
    sweep, from their lines of sight at the scan's two farthest columns (the spacecraft at each pixel's
    time), turned towards the velocity. VIIRS scans the SBF's y-z plane; the SBF is yawed against the
    ECEF velocity (~3.5 degrees at the equator), which at a 50 degree scan angle is ~70 mrad in-track.
    NaN when no column holds both."""
    out = np.full(3, np.nan)
    first, last = -1, -1
    for c in range(good.shape[1]):
        if good[15, c] and good[16, c]:
            last = c
            if first < 0:
                first = c
    if first < 0 or last == first:
        return out
    rays = np.empty((2, 3))
    for n, c in enumerate((first, last)):
        ray = np.zeros(3)
        for i in (15, 16):
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
    x: np.ndarray,
    b: np.ndarray,
    a: np.ndarray,
) -> None:
    """Fill *x*, *b* and *a* (:func:`view_tangents`), one scan a task; x along the first scan's SBF x."""
    cols = lat.shape[1]
    axis0 = np.full(3, np.nan)
    for k in range(lat.shape[0] // VIIRS_DETECTORS):  # the first scan with an SBF: x's axis
        if np.all(np.isfinite(sat[k])) and np.all(np.isfinite(vel[k])):
            point = np.empty((VIIRS_DETECTORS, cols, 7))
            rows = good[k * VIIRS_DETECTORS : (k + 1) * VIIRS_DETECTORS]
            order = scan_points(lat, lon, h, rows, k * VIIRS_DETECTORS, sat[k], vel[k], point)
            if order != 0.0:
                axis0 = _scan_normal(point, rows, sat[k], vel[k], order)
                if np.all(np.isfinite(axis0)):
                    break
    if not np.all(np.isfinite(axis0)):
        return
    for k in numba.prange(lat.shape[0] // VIIRS_DETECTORS):
        if not (np.all(np.isfinite(sat[k])) and np.all(np.isfinite(vel[k]))):
            continue
        row0 = k * VIIRS_DETECTORS
        rows = good[row0 : row0 + VIIRS_DETECTORS]
        point = np.empty((VIIRS_DETECTORS, cols, 7))
        order = scan_points(lat, lon, h, rows, row0, sat[k], vel[k], point)
        if order == 0.0:
            continue
        s = sat[k]
        v = vel[k]
        xs = _scan_normal(point, rows, s, v, order)
        if not np.all(np.isfinite(xs)):
            continue
        for i in range(VIIRS_DETECTORS):
            for c in range(cols):
                if not rows[i, c]:
                    continue
                q = point[i, c]
                p = q[:3]
                up = q[3:6]
                track = xs - (xs @ up) * up  # the SBF's x on the horizontal at the point: a column's way
                track = track / math.sqrt(track @ track)
                x[row0 + i, c] = p @ axis0
                d = s + v * (order * q[6] / ROTATION_RAD_S) - p  # to VIIRS at the pixel's time
                b[row0 + i, c] = (d @ track) / (d @ up)
                for j in range(tan_alpha.shape[0]):
                    dr = d.copy()
                    for _ in range(3):  # the SBF turns with the spacecraft's move: 11 % of it, then 1 %
                        sr = p + dr
                        zs = -sr / math.sqrt(sr @ sr)
                        xj = xs - (xs @ zs) * zs
                        xj = xj / math.sqrt(xj @ xj)
                        zs = zs - (zs @ xj) * xj
                        zs = zs / math.sqrt(zs @ zs)
                        # along the track by dt: (P - S') . x = tan(alpha) (P - S') . z
                        dt = (-(dr @ xj) + tan_alpha[j] * (dr @ zs)) / (v @ xj - tan_alpha[j] * (v @ zs))
                        dr = dr + dt * v
                    a[j, row0 + i, c] = (dr @ track) / (dr @ up)


def render_columns(
    x_m: np.ndarray,
    width_m: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    reference_k: np.ndarray,
    viirs_tan: np.ndarray,
    cris_tan: np.ndarray,
    m_per_k: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The BT (K) a CrIS FOV row's ray meeting the ground at each pixel's GEO point sees first, and what
    it meets there (0: that pixel's own top, 1: another column's top, 2: a wall; see the module
    docstring), for columns of pixels sorted along the track: all arrays (n, columns), x_m ascending in
    each column (NaN: no pixel; its BT is NaN), *height_m* >= 0 the pixels' heights, *viirs_tan* and
    *cris_tan* the in-track tangents of the VIIRS ray of each pixel and of the CrIS row's ray at each
    GEO point (towards the spacecraft, positive along +x), *reference_k* the clear-sky reference BT the
    walls' temperatures are counted down from at *m_per_k* (m per K)."""
    arrays = [np.ascontiguousarray(a, np.float64) for a in (x_m, width_m, height_m, bt_k, reference_k)]
    tans = [np.ascontiguousarray(a, np.float64) for a in (viirs_tan, cris_tan)]
    seen = np.full(np.shape(x_m), np.nan)
    kind = np.zeros(np.shape(x_m), np.int8)
    with KERNEL_LOCK:
        _render(*arrays, *tans, float(m_per_k), seen, kind)
    return seen, kind


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _first_hit(x: float, a: float, t: float, half: float, h: float) -> float:
    """The highest z (m) at which the ray x + z a is inside the column |x - t| <= half, 0 <= z <= h;
    -1 when it never is."""
    if a == 0.0:
        return h if abs(x - t) <= half else -1.0
    z1 = (t - half - x) / a
    z2 = (t + half - x) / a
    lo, hi = min(z1, z2), max(z1, z2)
    top = min(h, hi)
    return top if top >= max(lo, 0.0) else -1.0


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _render(
    x: np.ndarray,
    w: np.ndarray,
    h: np.ndarray,
    bt: np.ndarray,
    ref: np.ndarray,
    b: np.ndarray,
    a: np.ndarray,
    m_per_k: float,
    seen: np.ndarray,
    kind: np.ndarray,
) -> None:
    """Fill *seen* and *kind* (:func:`render_columns`), one column a task."""
    n, ncol = x.shape
    for c in numba.prange(ncol):
        h_max, b_max, w_max = 0.0, 0.0, 0.0
        for j in range(n):
            if math.isfinite(x[j, c]):
                h_max = max(h_max, h[j, c])
                b_max = max(b_max, abs(b[j, c]))
                w_max = max(w_max, w[j, c])
        for i in range(n):
            xi, ai = x[i, c], a[i, c]
            if not (math.isfinite(xi) and math.isfinite(ai)):
                continue
            reach = 0.5 * w_max + h_max * (abs(ai) + b_max)
            best_z, best_d, best_j, best_wall = -1.0, math.inf, -1, False
            for step in (-1, 1):
                j = i if step == 1 else i - 1
                while 0 <= j < n:
                    xj = x[j, c]
                    if math.isfinite(xj):
                        if abs(xj - xi) > reach:
                            break
                        t = xj + h[j, c] * b[j, c]
                        z = _first_hit(xi, ai, t, 0.5 * w[j, c], h[j, c])
                        if z >= 0.0:
                            d = abs(xi + h[j, c] * ai - t)  # the ray's distance from the top's centre
                            if z > best_z + 1e-6 or (abs(z - best_z) <= 1e-6 and d < best_d):
                                best_z, best_d, best_j = z, d, j
                                best_wall = z < h[j, c] - 1e-6
                    j += step
            if best_j < 0:  # in no column (a gap between pixels): its own pixel
                seen[i, c], kind[i, c] = bt[i, c], 0
            elif best_wall:
                seen[i, c], kind[i, c] = ref[best_j, c] - best_z / m_per_k, 2
            else:
                seen[i, c], kind[i, c] = bt[best_j, c], 0 if best_j == i else 1
