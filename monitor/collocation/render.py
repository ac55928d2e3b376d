"""What a CrIS FOV row sees of a VIIRS granule whose pixels stand at a height: hidden ground out, walls in.

The point lift (:mod:`monitor.collocation.lift`) moves each pixel up its VIIRS line of sight to the height
its BT implies and lets the cone test look at the lifted points from CrIS. From an outer FOV row's slant
view that still counts ground a lifted cloud hides, and misses the cloud's side (its wall) that the view
meets (docs/science.md, "Clouds have height"). This module renders instead what the ray of a CrIS FOV row
that meets the ground at each pixel's GEO point meets first; the cone test can then keep every pixel at its
GEO point and give it that radiance (the rays through a ground patch are the rays its solid angle holds).

**The geometry.** x is along the track and y across (m); z up (m). VIIRS saw pixel (r, c) along the ray
that climbs b (in-track) and t (across) metres per metre of height from its GEO point; a CrIS row's ray to
the same point climbs a along the track and the same t across (one spacecraft, one scan angle; only the
time, and so the in-track angle, differs). So in one column's slanted plane the two differ in-track only,
but what lies *below* what VIIRS saw in that plane is not a column of cloud: off nadir the plane cuts the
vertical clouds obliquely, and a hit on a cloud's side seen across the track floats above clear air in
it. A render in the slanted plane alone (this module's first form) therefore failed off nadir: against the
simulator's own ray tracing, its rows' views were worse than the pixels' own BT even at 0.3 of a tangent
across. The clouds are vertical columns on the ground instead:

1. :func:`_splat`: each pixel stands where VIIRS met it, (x + h b, y + h t), as the top of a vertical
   column h high with its BT, on a grid of the granule's GEO points with :data:`SUB` cells across per
   pixel column (a slope's hits crowd closer than a column; the highest wins); cells no hit stands on take
   the lower of their nearest neighbours across (:func:`_fill`).
2. :func:`_march`: each CrIS ray starts just above where it first comes down to what VIIRS saw in its
   slanted plane (above that it is in air VIIRS looked through: :func:`_slant_start`) and steps down a
   cell at a time (at most :data:`STEP_M`) until it is in a column whose top is above it: that top's BT
   if it came down through the top, a wall's (the top's BT plus the depth below it over kappa, the day's
   height law) if through a side; at the ground, the column there.

Measured (2026-11-28, ``tests/collocation/test_render.py``): on opaque blocks whose edges fall between
pixels, VIIRS's own view gives back its BT (to 1.2 K where it met a side across the track: a quarter
column of a ray's height), and the rows' views agree with a brute-force march within 2 K at 99.9 % of the
GEO points at nadir, 99.9 % at 0.3 across and 99.7 % at the swath's edge (1.1 across; a ray there crosses
35 columns, so a granule's first and last MARGIN_COLUMNS are rendered with their neighbours), where the
pixels' own BT is more than 5 K off at 0.4-0.9 %. Not yet used by the assessment (issue 57): it is slow
(a whole granule at 5 views: 36 s, 66 CPU s on the 2-core machine, where the point lift lifts one in 2.9
s), and a granule's first and last rows are rendered without the next granule's pixels.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from monitor.collocation.lift import ROTATION_RAD_S, height_above_m, reference_k, scan_points
from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.constants import VIIRS_DETECTORS

COLUMNS_PER_PASS = 512  # columns rendered at a time: the sort's and the tangents' arrays stay ~60 MB
SUB = 4  # the field's cells across the track per pixel column: a slope's hits crowd closer than a column
FILL_CELLS = 3 * SUB  # how far across the track a cell no hit stands on looks for its neighbours
STEP_M = 100.0  # a ray's longest step down (m); where it came into a column is bisected to 0.4 m
BISECTIONS = 8
MARGIN_COLUMNS = 64  # columns on either side a ray can cross: 20 km up at a cross-track tangent of 1.3


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
    """The BT (K, float32 (len(cris_alpha_rad), rows, cols)) that a CrIS ray at each in-track SBF angle
    of *cris_alpha_rad* sees on its way to each GEO point of a VIIRS granule (rows of 32-detector scans,
    GEO (lat_rad, lon_rad, height_m), BT *bt_k*, usable where *good*; NaN elsewhere; ground VIIRS did
    not see shows its nearest neighbour's across the track, :func:`_fill`), each pixel standing *m_per_k*
    m per K colder than its clear-sky reference (:func:`monitor.collocation.lift.height_above_m`):
    :func:`view_tangents`, then
    :func:`render_height_field`, :data:`COLUMNS_PER_PASS` columns at a time with the
    :data:`MARGIN_COLUMNS` about them that their rays can cross."""
    rows, cols = np.shape(bt_k)
    out = np.full((len(cris_alpha_rad), rows, cols), np.nan, np.float32)
    usable = np.asarray(good, bool) & np.isfinite(bt_k)
    reference = reference_k(bt_k, usable)  # over the whole granule: it looks 40 pixels around
    height = height_above_m(bt_k, usable, reference, m_per_k)
    for c0 in range(0, cols, COLUMNS_PER_PASS):
        c1 = min(c0 + COLUMNS_PER_PASS, cols)
        lo, hi = max(c0 - MARGIN_COLUMNS, 0), min(c1 + MARGIN_COLUMNS, cols)
        part = slice(lo, hi)
        ok = usable[:, part]
        x, b, a, across = view_tangents(
            lat_rad[:, part], lon_rad[:, part], height_m[:, part], ok, sat_m, velocity_m_s, cris_alpha_rad
        )
        seen = render_height_field(
            np.where(ok, x, np.nan), b, across, np.where(ok, height[:, part], 0.0), bt_k[:, part], a, m_per_k
        )
        keep = slice(c0 - lo, c1 - lo)
        out[:, :, c0:c1] = np.where(ok[:, keep], seen[:, :, keep], np.nan)
    return out


def view_tangents(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
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
    across = np.zeros((rows, cols), np.float32)
    geo = [np.ascontiguousarray(v, np.float64) for v in (lat_rad, lon_rad, height_m)]
    tan_alpha = np.tan(np.asarray(cris_alpha_rad, np.float64))
    with KERNEL_LOCK:
        _tangents(*geo, np.ascontiguousarray(good, np.bool_), sat, vel, tan_alpha, x, b, a, across)
    return x, b, a, across


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
    across: np.ndarray,
) -> None:
    """Fill *x*, *b*, *a* and *across* (:func:`view_tangents`), one scan a task; x along the first scan's
    SBF x."""
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
                lo, hi = max(c - 1, 0), min(c + 1, cols - 1)
                while lo < c and not rows[i, lo]:
                    lo += 1
                while hi > c and not rows[i, hi]:
                    hi -= 1
                if hi > lo:
                    side = np.cross(up, track)
                    step = ((point[i, hi, :3] - point[i, lo, :3]) @ side) / (hi - lo)
                    across[row0 + i, c] = (d @ side) / (d @ up) / step
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


def render_height_field(
    x_m: np.ndarray,
    viirs_tan: np.ndarray,
    across_per_m: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    cris_tan: np.ndarray,
    m_per_k: float,
) -> np.ndarray:
    """What a CrIS ray at each in-track tangent of *cris_tan* (views, rows, cols) sees on its way to each
    GEO point (float32 (views, rows, cols), K; NaN where x is, and where it reaches a cell no hit stands
    near, :func:`_fill`). The granule's pixels (rows, cols; *x_m* their along-track GEO coordinate, NaN
    where unusable), seen by VIIRS at *height_m* along rays of in-track tangent *viirs_tan* and
    *across_per_m* columns per metre of height (:func:`view_tangents`), make a field of vertical columns
    (:func:`_splat`); each CrIS ray is marched down through it (:func:`_march`). Walls are their column's
    top's BT plus their depth below it over *m_per_k* (m per K)."""
    rows, cols = np.shape(x_m)
    x = np.ascontiguousarray(x_m, np.float64)
    xs, rank, order = _along(x)
    count = np.isfinite(xs).sum(axis=0).astype(np.int64)
    with np.errstate(all="ignore"):
        spacing = np.nan_to_num(np.nanmedian(np.diff(xs, axis=0), axis=0), nan=400.0)
    args = [np.ascontiguousarray(v, np.float64) for v in (viirs_tan, across_per_m, height_m, bt_k)]
    slant_sorted, slant_rank, slant_order = _along(x + args[2] * args[0])  # where VIIRS met each pixel
    slant_h = np.take_along_axis(args[2], slant_order, axis=0)
    top_m = np.full((rows, cols * SUB), np.nan)
    top_k = np.full((rows, cols * SUB), np.nan)
    seen = np.full((len(cris_tan), rows, cols), np.nan, np.float32)
    with KERNEL_LOCK:
        _splat(x, xs, rank, count, *args, top_m, top_k)
        _march(
            x, xs, rank, count, spacing, args[1], np.ascontiguousarray(cris_tan, np.float64), slant_sorted,
            slant_h, slant_rank, top_m, top_k, float(m_per_k), seen,
        )  # fmt: skip
    return seen


def _along(v: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each column of *v* (rows, cols) sorted ascending (NaN last), each row's place in its column's
    order, and the order."""
    order = np.argsort(np.where(np.isfinite(v), v, np.inf), axis=0, kind="stable")
    rank = np.empty(np.shape(v), np.int64)
    np.put_along_axis(rank, order, np.arange(len(v))[:, None].repeat(np.shape(v)[1], 1), axis=0)
    return np.take_along_axis(v, order, axis=0), rank, order


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _nearest(xs: np.ndarray, c: int, n: int, value: float, hint: int) -> int:
    """The index of the value nearest *value* among xs[:n, c] (ascending; the lower one of two as near),
    walked to from *hint* (a ray's own row's place there is a step or two away)."""
    k = min(max(hint, 0), n - 1)
    while k + 1 < n and abs(xs[k + 1, c] - value) < abs(xs[k, c] - value):
        k += 1
    while k > 0 and abs(xs[k - 1, c] - value) <= abs(xs[k, c] - value):
        k -= 1
    return k


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _splat(
    x: np.ndarray,
    xs: np.ndarray,
    rank: np.ndarray,
    count: np.ndarray,
    b: np.ndarray,
    across: np.ndarray,
    h: np.ndarray,
    bt: np.ndarray,
    top_m: np.ndarray,
    top_k: np.ndarray,
) -> None:
    """Stand each pixel VIIRS saw above the ground where it saw it: the column (sorted position, column)
    under its hit gets its height and BT (the highest hit there wins)."""
    rows, cols = x.shape
    for r in range(rows):
        for c in range(cols):
            if not math.isfinite(x[r, c]):
                continue
            f = int(round((c + h[r, c] * across[r, c]) * SUB))
            c2 = int(round(f / SUB))
            if f < 0 or c2 >= cols or count[c2] == 0:
                continue
            base = x[r, c2] if math.isfinite(x[r, c2]) else x[r, c]
            k = _nearest(xs, c2, count[c2], base + h[r, c] * b[r, c], rank[r, c2])
            if not h[r, c] <= top_m[k, f]:  # NaN: none yet
                top_m[k, f] = h[r, c]
                top_k[k, f] = bt[r, c]
    _fill(xs, count, top_m, top_k)


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _fill(xs: np.ndarray, count: np.ndarray, top_m: np.ndarray, top_k: np.ndarray) -> None:
    """Give the cells no VIIRS hit stands on (NaN height: the splat's rounding skipped them, or VIIRS did
    not see there) the lower of the nearest hits across the track within FILL_CELLS (0 and NaN where
    none: no cloud is known there); only hits are looked at, not cells filled before."""
    cols = xs.shape[1]
    hit_m = top_m.copy()
    hit_k = top_k.copy()
    for f in numba.prange(cols * SUB):
        c = min(int(round(f / SUB)), cols - 1)
        for k in range(count[c]):
            if math.isfinite(hit_m[k, f]):
                continue
            best_m, best_k = np.inf, np.nan
            for step in (-1, 1):
                for d in range(1, FILL_CELLS + 1):
                    f2 = f + step * d
                    c2 = int(round(f2 / SUB))
                    if f2 < 0 or c2 >= cols or count[c2] == 0:
                        break
                    k2 = k if c2 == c else _nearest(xs, c2, count[c2], xs[k, c], k)
                    if math.isfinite(hit_m[k2, f2]):
                        if hit_m[k2, f2] < best_m:
                            best_m, best_k = hit_m[k2, f2], hit_k[k2, f2]
                        break
            top_m[k, f] = best_m if math.isfinite(best_m) else 0.0
            top_k[k, f] = best_k


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _march(
    x: np.ndarray,
    xs: np.ndarray,
    rank: np.ndarray,
    count: np.ndarray,
    spacing: np.ndarray,
    across: np.ndarray,
    a: np.ndarray,
    slant: np.ndarray,
    slant_h: np.ndarray,
    slant_rank: np.ndarray,
    top_m: np.ndarray,
    top_k: np.ndarray,
    m_per_k: float,
    seen: np.ndarray,
) -> None:
    """Fill *seen* (:func:`render_height_field`), one column a task. A ray is free above what VIIRS saw
    in its slanted plane (the pixels of its column, by where VIIRS met them: *slant*, *slant_h* sorted
    along the track, *slant_rank* each pixel's place there), so it starts where it first comes down to
    that (:func:`_slant_start`), two steps higher; from there it steps down through the field of vertical
    columns (a cell at a time in either direction, at most STEP_M) to the first column whose top is above
    it, and bisects between the last two steps for where it came in: at that column's top (its BT), or
    through its side (a wall: the top's BT plus the depth below it over *m_per_k*). A column it leaves
    between two steps is met at its top if the ray is still over it there."""
    rows, cols = x.shape
    tops_m, tops_k = top_m.reshape(-1), top_k.reshape(-1)  # by :func:`_cell_at`'s index
    for c in numba.prange(cols):
        n_slant = 0
        h_max, w_max = 0.0, 0.0
        while n_slant < rows and math.isfinite(slant[n_slant, c]):
            h_max = max(h_max, slant_h[n_slant, c])
            if n_slant > 0:
                w_max = max(w_max, slant[n_slant, c] - slant[n_slant - 1, c])
            n_slant += 1
        for r in range(rows):
            if not math.isfinite(x[r, c]):
                continue
            for v in range(a.shape[0]):
                av = a[v, r, c]
                rate = max(abs(av) / spacing[c], SUB * abs(across[r, c]), 1e-9)  # cells per metre of height
                start = _slant_start(x[r, c], av, slant, slant_h, slant_rank[r, c], c, n_slant, h_max, w_max)
                dz = min(1.0 / rate, STEP_M)
                z_top = start + 2.0 * dz
                steps = max(1, int(math.ceil(z_top / dz)))
                value = np.nan
                above = z_top
                last = -1
                for n in range(steps + 1):
                    z = z_top * (1.0 - n / steps)
                    if last >= 0 and tops_m[last] > z:  # did it pass below that top before it left?
                        if _cell_at(x, xs, rank, count, across, r, c, av, tops_m[last]) == last:
                            value = tops_k[last]
                            break
                    cell = _cell_at(x, xs, rank, count, across, r, c, av, z)
                    if cell >= 0 and tops_m[cell] >= z:  # in a column: find where it came in
                        low = z
                        for _ in range(BISECTIONS):
                            mid = 0.5 * (low + above)
                            inner = _cell_at(x, xs, rank, count, across, r, c, av, mid)
                            if inner >= 0 and tops_m[inner] >= mid:
                                low, cell = mid, inner
                            else:
                                above = mid
                        value = tops_k[cell] + (tops_m[cell] - low) / m_per_k
                        break
                    above, last = z, cell
                seen[v, r, c] = value


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _cell_at(
    x: np.ndarray,
    xs: np.ndarray,
    rank: np.ndarray,
    count: np.ndarray,
    across: np.ndarray,
    r: int,
    c: int,
    a: float,
    z: float,
) -> int:
    """The cell (sorted position x cells + fine column) the ray of pixel (r, c) climbing *a* along the
    track is over at height *z*; -1 off the granule."""
    cols = x.shape[1]
    f = int(round((c + z * across[r, c]) * SUB))
    c2 = int(round(f / SUB))
    if f < 0 or c2 >= cols or count[c2] == 0:
        return -1
    base = x[r, c2] if math.isfinite(x[r, c2]) else x[r, c]
    return _nearest(xs, c2, count[c2], base + z * a, rank[r, c2]) * (cols * SUB) + f  # tops_m's index


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _slant_start(
    x: float,
    a: float,
    slant: np.ndarray,
    slant_h: np.ndarray,
    i: int,
    c: int,
    n: int,
    h_max: float,
    w_max: float,
) -> float:
    """The highest z (m) at which the ray x + z a is at or below what VIIRS saw in its slanted plane:
    pixel j's height over the stretch halfway to its neighbours about where VIIRS met it (column c of
    *slant*, *slant_h*, n pixels, the ray's own at i)."""
    reach = w_max + h_max * abs(a)
    best = 0.0
    for step in (-1, 1):
        j = i if step == 1 else i - 1
        while 0 <= j < n:
            if step * (slant[j, c] - x) > reach:
                break
            left = 0.5 * (slant[j - 1, c] + slant[j, c]) if j > 0 else -np.inf
            right = 0.5 * (slant[j, c] + slant[j + 1, c]) if j < n - 1 else np.inf
            if a == 0.0:
                top = slant_h[j, c] if left <= x <= right else -1.0
            else:
                z1, z2 = (left - x) / a, (right - x) / a
                top = min(slant_h[j, c], max(z1, z2))
                if top < max(min(z1, z2), 0.0):
                    top = -1.0
            best = max(best, top)
            j += step
    return best
