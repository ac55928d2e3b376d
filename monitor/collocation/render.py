"""What a CrIS FOV row sees of a VIIRS granule whose pixels stand at a height: hidden ground out, walls in.

Each pixel stands at the height its BT implies (:mod:`monitor.collocation.lift`). From an outer CrIS FOV
row's slant view (19.1 mrad ahead or behind, Wang et al. 2017 section 2.1) a high cloud hides ground that
VIIRS saw and shows a side (its wall) that VIIRS did not. This module renders what the ray of a CrIS FOV row
that meets the ground at each pixel's GEO point meets first (docs/science.md, "Clouds with height"). The
cone test then keeps every pixel at its GEO point and gives it that radiance: the rays through a ground
patch are the rays its solid angle holds.

**The geometry.** Along one VIIRS column, x runs along the track on the ground (m) and z up (m). VIIRS saw
pixel r of the column along the ray x_r + z b_r from its GEO point x_r, and met what it saw at the height
h_r (the lift: :func:`monitor.collocation.lift.height_above_m`), at

    p_r = x_r + h_r b_r.

A CrIS row at in-track SBF angle alpha sees the same GEO point along x_r + z a_r, across the track as VIIRS
does (one spacecraft, one scan angle; only the time, and so the in-track tangent, differs:
:func:`monitor.collocation.views.view_tangents`). So the column's rays of both instruments lie in one slanted
plane, and in it:

1. what VIIRS saw is a profile: pixel j stands h_j high over the stretch of the plane halfway to its
   neighbours' hits (p_j sorted along the track);
2. the CrIS ray comes down x_r + z a_r and meets the first stretch whose top is above it, at the height

       z_j = min(h_j, max(z_in, z_out)),   z_in, z_out = (edge - x_r) / a_r at the stretch's two edges,

   a top where z_j = h_j, a wall (the stretch's side) where the ray passes it lower;
3. a top gives the BT of the two hits about where the ray meets it, interpolated linearly along the
   track; a wall gives its stretch's BT plus its depth below the top over kappa (the day's height law, m
   per K), the temperature of the air at that height.

Pixels hidden behind a higher one drop out (the ray meets the higher first), and the walls the ray meets
come in. Which stretch a ray meets is found in its column alone: the sweep is one dimension per column.
One column index of two scans is not one line on the ground (the Earth turns 1-2 columns under the track
between scans, and the bow-tie's smile puts a scan's outer detectors a few hundredths of a column further
out), and a CrIS ray is tilted across the track against VIIRS's. So a ray takes the BT of what it meets at
its own place across the track (:func:`monitor.collocation.views.view_tangents_across`), linearly between
the two columns of the met pixel's row about that place, up to :data:`ACROSS_COLUMNS` columns aside (a pixel
of the next or the last scan at one column index lies about two columns aside where the scans overlap).
A granule's first and last rows are rendered without the next granule's pixels.

:func:`rendered_bt` is the assessment's rendering. Two building blocks beside it are for studies:
:func:`swept_bt`, the sweep alone (each ray takes the met pixel's own BT, and where scans overlap a top's BT
comes from a pixel a column or two aside), and :func:`rendered_met`, the rendering with what each ray met
(:class:`Met`). A study puts another rendering in this one's place through the assessment's one seam for
studies (:class:`monitor.assessment.seam.Variation`); ``studies/render_truth.py`` measures this one against
the simulator's own views.
"""

from __future__ import annotations

import enum
import math
from typing import Protocol

import numba
import numpy as np

from monitor.collocation.lift import REFERENCE_HALF_PX, height_above_m, reference_k, running_max
from monitor.collocation.views import TANGENT_STEP, Across, view_tangents, view_tangents_across
from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.constants import VIIRS_DETECTORS

COLUMNS_PER_PASS = 512  # columns rendered at a time: the tangents of five views stay ~8 MB a pass
# The in-track SBF angles rendered (rad). A CrIS FOV's alpha is within +-27 mrad (a corner FOV turned with
# the scan); each FOV sees the two views about its own, weighted linearly (monitor.collocation.collocate).
VIEW_ALPHA_RAD = np.linspace(-0.04, 0.04, 5)
TOP_M = 1.0  # a ray that meets a stretch more than this below its top met its wall
NEAR_HITS = 16  # a ray's reach is bounded by the highest pixel within this many hits of its own
# A ray's place across the track is looked up this many columns either side of the pixel it meets, at most:
# between two scans the Earth turns ~2 columns under the track, the bow-tie's smile adds hundredths
ACROSS_COLUMNS = 3


class Met(enum.IntEnum):
    """What a ray met (:func:`rendered_met`): its own pixel's top, the top of another
    pixel of its scan or of another scan (at one column index, where scans overlap), or a wall; NOTHING where
    no ray was rendered."""

    OWN_TOP = 0
    SCAN_TOP = 1
    OTHER_SCAN_TOP = 2
    WALL = 3
    NOTHING = 255


class Renderer(Protocol):
    """What renders a VIIRS granule as CrIS FOV rows see it: :func:`rendered_bt`'s signature, so that a study
    can put another rendering, or a truth, in its place (:class:`monitor.assessment.seam.Variation`)."""

    def __call__(
        self,
        lat_rad: np.ndarray,
        lon_rad: np.ndarray,
        height_m: np.ndarray,
        bt_k: np.ndarray,
        good: np.ndarray,
        sat_m: np.ndarray,
        velocity_m_s: np.ndarray,
        cris_alpha_rad: np.ndarray,
        m_per_k: float,
        scans: slice = ...,
        columns: slice = ...,
        detectors: int = ...,
    ) -> np.ndarray: ...


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
    scans: slice = slice(None),
    columns: slice = slice(None),
    detectors: int = VIIRS_DETECTORS,
) -> np.ndarray:
    """The BT a CrIS ray at each in-track angle sees on its way to each GEO point of a VIIRS granule.

    :func:`~monitor.collocation.views.view_tangents_across`, then :func:`render_height_field`,
    :data:`COLUMNS_PER_PASS` columns at a time (each pass renders :data:`ACROSS_COLUMNS` columns more either
    side, so that its edge columns have their neighbours). The clear-sky reference is the whole granule's.
    Each ray takes its BT at its own position across the track.

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    bt_k : numpy.ndarray
        The pixels' band BT, K, shape (rows, cols).
    good : numpy.ndarray
        Where a pixel is usable.
    sat_m, velocity_m_s : numpy.ndarray
        Each scan's spacecraft position (m) and velocity (m/s) at its middle, ECEF, shape (nscan, 3).
    cris_alpha_rad : numpy.ndarray
        The CrIS views' in-track angles in the spacecraft body frame, rad, positive ahead.
    m_per_k : float
        The lift: each pixel stands this many m per K colder than its clear-sky reference
        (:func:`monitor.collocation.lift.height_above_m`).
    scans : slice, optional
        The scans to render (step 1).
    columns : slice, optional
        The columns to render.
    detectors : int, optional
        The rows of a scan (the grid's detectors: :data:`monitor.core.bands.GRIDS`).

    Returns
    -------
    numpy.ndarray
        BT, K, float32, shape (len(cris_alpha_rad), rows, cols); NaN outside *scans* and *columns* and where
        unusable.
    """
    return _render(
        lat_rad, lon_rad, height_m, bt_k, good, sat_m, velocity_m_s, cris_alpha_rad, m_per_k, scans, columns,
        detectors, across=True, met=None,
    )  # fmt: skip


def swept_bt(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
    m_per_k: float,
    scans: slice = slice(None),
    columns: slice = slice(None),
    detectors: int = VIIRS_DETECTORS,
) -> np.ndarray:
    """:func:`rendered_bt` with the sweep alone: each ray takes the BT of the pixel it meets, not of its own
    place across the track (:func:`~monitor.collocation.views.view_tangents`).

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    bt_k : numpy.ndarray
        The pixels' band BT, K, shape (rows, cols).
    good : numpy.ndarray
        Where a pixel is usable.
    sat_m, velocity_m_s : numpy.ndarray
        Each scan's spacecraft position (m) and velocity (m/s) at its middle, ECEF, shape (nscan, 3).
    cris_alpha_rad : numpy.ndarray
        The CrIS views' in-track angles in the spacecraft body frame, rad, positive ahead.
    m_per_k : float
        The lift: each pixel stands this many m per K colder than its clear-sky reference
        (:func:`monitor.collocation.lift.height_above_m`).
    scans : slice, optional
        The scans to render (step 1).
    columns : slice, optional
        The columns to render.
    detectors : int, optional
        The rows of a scan (the grid's detectors: :data:`monitor.core.bands.GRIDS`).

    Returns
    -------
    numpy.ndarray
        BT, K, float32, shape (len(cris_alpha_rad), rows, cols); NaN outside *scans* and *columns* and where
        unusable.
    """
    return _render(
        lat_rad, lon_rad, height_m, bt_k, good, sat_m, velocity_m_s, cris_alpha_rad, m_per_k, scans, columns,
        detectors, across=False, met=None,
    )  # fmt: skip


def rendered_met(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
    m_per_k: float,
    scans: slice = slice(None),
    columns: slice = slice(None),
    detectors: int = VIIRS_DETECTORS,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`rendered_bt`, and what each ray met (:class:`Met`): a study's view of the rendering.

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    bt_k : numpy.ndarray
        The pixels' band BT, K, shape (rows, cols).
    good : numpy.ndarray
        Where a pixel is usable.
    sat_m, velocity_m_s : numpy.ndarray
        Each scan's spacecraft position (m) and velocity (m/s) at its middle, ECEF, shape (nscan, 3).
    cris_alpha_rad : numpy.ndarray
        The CrIS views' in-track angles in the spacecraft body frame, rad, positive ahead.
    m_per_k : float
        The lift: each pixel stands this many m per K colder than its clear-sky reference
        (:func:`monitor.collocation.lift.height_above_m`).
    scans : slice, optional
        The scans to render (step 1).
    columns : slice, optional
        The columns to render.
    detectors : int, optional
        The rows of a scan (the grid's detectors: :data:`monitor.core.bands.GRIDS`).

    Returns
    -------
    bt_k : numpy.ndarray
        As :func:`rendered_bt` returns it.
    met : numpy.ndarray
        What each ray met (:class:`Met`), uint8, the same shape.
    """
    met = np.empty((len(cris_alpha_rad), *np.shape(bt_k)), np.uint8)
    bt = _render(
        lat_rad, lon_rad, height_m, bt_k, good, sat_m, velocity_m_s, cris_alpha_rad, m_per_k, scans, columns,
        detectors, across=True, met=met,
    )  # fmt: skip
    return bt, met


def _render(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    good: np.ndarray,
    sat_m: np.ndarray,
    velocity_m_s: np.ndarray,
    cris_alpha_rad: np.ndarray,
    m_per_k: float,
    scans: slice,
    columns: slice,
    detectors: int,
    across: bool,
    met: np.ndarray | None,
) -> np.ndarray:
    """:func:`rendered_bt` (*across*) or :func:`swept_bt`, filling *met* where given."""
    rows, cols = np.shape(bt_k)
    out = np.empty((len(cris_alpha_rad), rows, cols), np.float32)
    usable = np.asarray(good, bool) & np.isfinite(bt_k)
    # over the whole granule, as far around on the ground on either grid (an M pixel spans two I pixels)
    reference = reference_k(bt_k, usable, REFERENCE_HALF_PX * detectors // VIIRS_DETECTORS)
    height = height_above_m(bt_k, usable, reference, m_per_k)
    first, stop, _ = scans.indices(rows // detectors)
    r = slice(first * detectors, stop * detectors)
    c_first, c_stop, _ = columns.indices(cols)
    c_stop = max(c_stop, c_first)
    # what the passes do not write: the passes write every pixel of r and [c_first, c_stop)
    out[:, : r.start], out[:, r.stop :] = np.nan, np.nan
    out[:, r, :c_first], out[:, r, c_stop:] = np.nan, np.nan
    if met is not None:
        met[...] = Met.NOTHING
    halo = ACROSS_COLUMNS if across else 0
    for c0 in range(c_first, c_stop, COLUMNS_PER_PASS):
        part = slice(c0, min(c0 + COLUMNS_PER_PASS, c_stop))
        drawn = slice(max(c0 - halo, 0), min(part.stop + halo, cols))  # the part and its halo
        # traced from the node at or before them to the node at or after: a part as in the whole
        lo = drawn.start - drawn.start % TANGENT_STEP
        hi = min(-(-(drawn.stop - 1) // TANGENT_STEP) * TANGENT_STEP + 1, cols)
        traced = slice(lo, hi)
        geo = (lat_rad[r, traced], lon_rad[r, traced], height_m[r, traced], usable[r, traced])
        orbit = (sat_m[first:stop], velocity_m_s[first:stop], cris_alpha_rad, lo)
        if across:
            x, b, a, sideways = view_tangents_across(*geo, *orbit, detectors=detectors)
        else:
            (x, b, a), sideways = view_tangents(*geo, *orbit, detectors=detectors), None
        shape = (len(cris_alpha_rad), r.stop - r.start, drawn.stop - drawn.start)
        kind = None if met is None else np.empty(shape, np.uint8)
        seen = render_height_field(
            x,  # NaN where unusable: traced with usable as the pixels' good
            b,
            height[r, traced],
            bt_k[r, traced],
            a,
            m_per_k,
            sideways,
            slice(drawn.start - lo, drawn.stop - lo),
            kind,
            detectors,
        )
        inner = slice(part.start - drawn.start, part.stop - drawn.start)
        out[:, r, part] = seen[:, :, inner]
        if met is not None and kind is not None:
            met[:, r, part] = kind[:, :, inner]
    return out


def render_height_field(
    x_m: np.ndarray,
    viirs_tan: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    cris_tan: np.ndarray,
    m_per_k: float,
    across: Across | None = None,
    columns: slice = slice(None),
    met: np.ndarray | None = None,
    detectors: int = VIIRS_DETECTORS,
) -> np.ndarray:
    """What a CrIS ray at each in-track tangent sees on its way to each GEO point: the module's sweep.

    With *across*, a ray takes the BT of what it meets at its own position across the track: from the
    pixel's row, linearly between the two columns about that place, up to :data:`ACROSS_COLUMNS` aside
    (the last usable column within *columns* where the row ends or a pixel is unusable before it).

    Parameters
    ----------
    x_m : numpy.ndarray
        Each GEO point's coordinate along the track, m, NaN where unusable, shape (rows, cols).
    viirs_tan : numpy.ndarray
        The in-track tangent of each pixel's VIIRS ray, shape (rows, cols).
    height_m : numpy.ndarray
        The height VIIRS saw each pixel at, m, shape (rows, cols).
    bt_k : numpy.ndarray
        The pixels' I5 BT, K, shape (rows, cols).
    cris_tan : numpy.ndarray
        The CrIS rays' in-track tangents, shape (views, rows, cols).
    m_per_k : float
        The height law, m per K: a wall is its stretch's BT plus its depth below the top over it.
    across : Across, optional
        Where the rays lie across the track (:func:`~monitor.collocation.views.view_tangents_across`), the
        same pixels.
    columns : slice, optional
        The columns rendered (step 1); the others are not read.
    met : numpy.ndarray, optional
        Filled with what each ray met (:class:`Met`), uint8, the output's shape.
    detectors : int, optional
        The rows of a scan: whether a ray met its own scan or another.

    Returns
    -------
    numpy.ndarray
        BT, K, float32, shape (views, rows, len(columns)); NaN where *x_m* is and in columns of fewer than 3
        usable pixels.
    """
    c_lo, c_hi, _ = columns.indices(np.shape(x_m)[1])
    seen = np.full((np.shape(cris_tan)[0], np.shape(x_m)[0], max(c_hi - c_lo, 0)), np.nan, np.float32)
    kind = np.full(seen.shape if met is not None else (0, 0, 0), Met.NOTHING, np.uint8)
    # one type for each argument, so that one compiled sweep serves every caller
    x = np.ascontiguousarray(x_m, np.float64)
    fields = [np.ascontiguousarray(v, np.float32) for v in (viirs_tan, height_m, bt_k, cris_tan)]
    if across is None:
        none = np.zeros((0, 0, 3))
        sideways = [none, none, np.zeros((0, 0), np.float32), np.zeros((0, 0, 0), np.float32)]
    else:
        sideways = [np.ascontiguousarray(v, np.float64) for v in (across.geo_m, across.unit)]
        sideways += [np.ascontiguousarray(v, np.float32) for v in (across.viirs_tan, across.cris_tan)]
    with KERNEL_LOCK:
        _sweep(x, *fields, float(m_per_k), *sideways, c_lo, c_hi, seen, kind, detectors)
    if met is not None:
        met[...] = kind
    return seen


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _across_bt(
    bt: np.ndarray,
    x: np.ndarray,
    geo: np.ndarray,
    unit: np.ndarray,
    b_across: np.ndarray,
    a_across: np.ndarray,
    v: int,
    r0: int,
    r: int,
    c: int,
    z: float,
    c_lo: int,
    c_hi: int,
) -> float:
    """The BT of pixel (r, c) at view v's ray to GEO point (r0, c) where it meets height z: the ray lies
    z (a - b) plus the two GEO points' distance across the track from that pixel's ray (both along the
    horizontal across at r0), taken linearly between the two columns of row r about that place, within
    :data:`ACROSS_COLUMNS` of c and [c_lo, c_hi); the farthest usable column on that side where the place
    lies beyond them (:func:`render_height_field`)."""
    own = bt[r, c]
    w0, w1, w2 = unit[r0, c, 0], unit[r0, c, 1], unit[r0, c, 2]
    apart = (geo[r, c, 0] - geo[r0, c, 0]) * w0 + (geo[r, c, 1] - geo[r0, c, 1]) * w1
    apart += (geo[r, c, 2] - geo[r0, c, 2]) * w2
    off = z * (np.float64(a_across[v, r0, c]) - b_across[r, c]) - apart
    if not math.isfinite(off) or off == 0.0:
        return own
    for step in (1, -1):
        before, at = own, 0.0  # the last column passed on this side: its BT, its distance across from c
        for k in range(1, ACROSS_COLUMNS + 1):
            n = c + k * step
            if n < c_lo or n >= c_hi or not math.isfinite(x[r, n]):
                break
            spacing = (geo[r, n, 0] - geo[r, c, 0]) * w0 + (geo[r, n, 1] - geo[r, c, 1]) * w1
            spacing += (geo[r, n, 2] - geo[r, c, 2]) * w2
            share = (off - at) / (spacing - at)
            if not share > 0.0:  # on the other side of c (k = 1), or the columns fold back
                break
            if share <= 1.0:
                return before + share * (bt[r, n] - before)
            before, at = bt[r, n], spacing
        if at != 0.0:  # beyond the columns reached on this side
            return before
    return own


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _sweep(
    x: np.ndarray,
    b: np.ndarray,
    h: np.ndarray,
    bt: np.ndarray,
    a: np.ndarray,
    m_per_k: float,
    geo: np.ndarray,
    unit: np.ndarray,
    b_across: np.ndarray,
    a_across: np.ndarray,
    c_lo: int,
    c_hi: int,
    out: np.ndarray,
    kind: np.ndarray,
    det: int,
) -> None:
    """Fill *out* (:func:`render_height_field`: columns c_lo to c_hi; across the track where *geo* has
    rows; and *kind* with what each ray met, :class:`Met`, where it has rows), one column a task:
    the column's hits p sorted along the track, then per ray the stretches within its reach tested for
    where it meets them, the highest meeting kept. The reach: a GEO spacing behind the ray's foot (the
    stretch it stands on), and ahead, towards the spacecraft, a spacing plus the run along the ray of the
    column's highest pixel, or of the highest within NEAR_HITS hits of its own in the sorted order when
    that reach stays among them: a stretch farther than its own height's run is met below ground. It is
    found by stepping from the foot's own hit, not by bisection: a few steps, where a search of 1536 hits
    takes eleven."""
    rows = x.shape[0]
    sideways = geo.shape[0] > 0
    told = kind.shape[0] > 0
    for c in numba.prange(c_lo, c_hi):
        usable = np.empty(rows, np.int64)
        n = 0
        for r in range(rows):
            if math.isfinite(x[r, c]):
                usable[n] = r
                n += 1
        if n < 3:
            continue
        idx = usable[:n]
        hit, foot = np.empty(n), np.empty(n)
        h_max = -np.inf
        for q in range(n):
            r = idx[q]
            hit[q] = x[r, c] + np.float64(h[r, c]) * b[r, c]
            foot[q] = x[r, c]
            h_max = max(h_max, np.float64(h[r, c]))
        order = np.argsort(hit)
        ps, rs = hit[order], idx[order]
        place = np.empty(rows, np.int64)  # each row's place in the sorted hits
        sorted_h = np.empty(n)
        for j in range(n):
            place[rs[j]] = j
            sorted_h[j] = h[rs[j], c]
        spacing = np.median(np.diff(np.sort(foot)))
        near_max = np.empty(n)
        running_max(sorted_h, NEAR_HITS, near_max)
        for j in range(n):
            near_max[j] = max(near_max[j], 0.0)  # no lower than the ground
        for v in range(a.shape[0]):
            for r0 in idx:
                s0, av = x[r0, c], np.float64(a[v, r0, c])
                own = place[r0]
                lo, hi = _reach(ps, own, s0, av, spacing, h_max)
                if lo >= own - NEAR_HITS and hi <= own + NEAR_HITS + 1:  # within what near_max bounds
                    lo, hi = _reach(ps, own, s0, av, spacing, near_max[own])
                best_z, best = -1.0, -1
                for j in range(lo, hi):
                    left = 0.5 * (ps[j - 1] + ps[j]) if j > 0 else -np.inf
                    right = 0.5 * (ps[j] + ps[j + 1]) if j < n - 1 else np.inf
                    hj = h[rs[j], c]
                    if av == 0.0:
                        z = hj if left <= s0 <= right else -1.0
                    else:
                        z1, z2 = (left - s0) / av, (right - s0) / av
                        z = min(hj, max(z1, z2))
                        if z < max(min(z1, z2), 0.0):  # the ray passes the stretch below ground
                            z = -1.0
                    if z > best_z:
                        best_z, best = z, j
                if best < 0:
                    continue
                top = h[rs[best], c]
                met = bt[rs[best], c]
                if told:
                    if top - best_z > TOP_M:
                        kind[v, r0, c - c_lo] = Met.WALL
                    elif rs[best] == r0:
                        kind[v, r0, c - c_lo] = Met.OWN_TOP
                    elif rs[best] // det == r0 // det:
                        kind[v, r0, c - c_lo] = Met.SCAN_TOP
                    else:
                        kind[v, r0, c - c_lo] = Met.OTHER_SCAN_TOP
                if top - best_z > TOP_M:  # a wall: the air's temperature at its depth
                    if sideways:
                        met = _across_bt(
                            bt, x, geo, unit, b_across, a_across, v, r0, rs[best], c, best_z, c_lo, c_hi
                        )
                    out[v, r0, c - c_lo] = met + (top - best_z) / m_per_k
                    continue
                at = s0 + best_z * av  # a top: the two hits about where the ray meets it, linearly
                k = best  # the last hit before it (a step from the stretch's own)
                while k >= 0 and ps[k] >= at:
                    k -= 1
                while k + 1 < n and ps[k + 1] < at:
                    k += 1
                if 0 <= k < n - 1 and ps[k + 1] > ps[k]:
                    w = (at - ps[k]) / (ps[k + 1] - ps[k])
                    before, after = bt[rs[k], c], bt[rs[k + 1], c]
                    if sideways:
                        before = _across_bt(
                            bt, x, geo, unit, b_across, a_across, v, r0, rs[k], c, best_z, c_lo, c_hi
                        )
                        after = _across_bt(
                            bt, x, geo, unit, b_across, a_across, v, r0, rs[k + 1], c, best_z, c_lo, c_hi
                        )
                    out[v, r0, c - c_lo] = (1 - w) * before + w * after
                elif sideways:
                    out[v, r0, c - c_lo] = _across_bt(
                        bt, x, geo, unit, b_across, a_across, v, r0, rs[best], c, best_z, c_lo, c_hi
                    )
                else:
                    out[v, r0, c - c_lo] = met


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _reach(ps: np.ndarray, own: int, s0: float, av: float, spacing: float, h_m: float) -> tuple[int, int]:
    """The sorted hits *ps* (from index lo to before hi) within a ray's reach (:func:`_sweep`): from s0
    - spacing to s0 + spacing + h_m |av| towards the spacecraft (its sign of *av*), found by stepping from
    the foot's own hit *own*."""
    run = h_m * abs(av)
    back, ahead = (spacing, spacing + run) if av >= 0.0 else (spacing + run, spacing)
    n = ps.shape[0]
    lo = own
    while lo > 0 and ps[lo - 1] >= s0 - back:
        lo -= 1
    while lo < n and ps[lo] < s0 - back:
        lo += 1
    hi = own
    while hi < n and ps[hi] < s0 + ahead:
        hi += 1
    while hi > 0 and ps[hi - 1] >= s0 + ahead:
        hi -= 1
    return lo, hi
