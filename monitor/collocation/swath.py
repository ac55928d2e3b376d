"""VIIRS granules prepared for the cone test: pixel points, band radiance, solid-angle weights, blocks. I5 on
the I grid (32-detector scans), or M15 on the M grid (16-detector scans: :data:`monitor.core.bands.GRIDS`).

Pixels where they are. A terrain-corrected (GITCO) pixel is the 3-D point where its line of sight meets
the terrain: (lat, lon, Height). Put at h = 0 instead, a pixel on terrain of height h seen from CrIS at
view zenith z moves by about h sin(z) / range towards nadir (~0.5 mrad for 1 km at the scan edge), so
every position below is the 3-D point; the ellipsoid product (GIMGO) has h = 0.

Weights. CrIS sees the scene averaged over the solid angle of its FOV; VIIRS pixels do not sample
that solid angle evenly (scan overlap towards the swath edge, footprint steps at the aggregation-zone
edges). Each pixel is weighted by the solid angle it covers seen from CrIS,
``w = |A . u| / range^2``, where ``A`` is the pixel's vector footprint (the cross product of the steps to
its neighbours, so that a slope is foreshortened as seen along the unit direction ``u`` from CrIS) with
the overlap between consecutive scans removed (the part of a footprint that a neighbouring scan also
covers counts half). The sum of the weights inside a cone over the cone's solid angle is its coverage:
1 when VIIRS fills it.

Search blocks. Each prepared granule keeps, per 4 x 4 block of pixels (blocks never straddle two scans),
a sphere holding its usable pixels, and a KD-tree of the block centres to find where a FOV lands. Only the
columns and scans a CrIS granule can reach are prepared (:mod:`monitor.collocation.reach`).

A granule is prepared once per run (about 10 million pixels), compiled (numba) and scan by scan in
parallel, with numba's numpy error model (a division by zero gives inf or NaN, which the kernels test for).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numba
import numpy as np
from scipy.spatial import cKDTree

from monitor.collocation.geodesy import ecef_m
from monitor.collocation.reach import BLOCK_PX, kept_pixels, search_spacings
from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.constants import VIIRS_DETECTORS


class BandTable(Protocol):
    """The I5 band's Planck table (:class:`monitor.instrument.spectral.BandModel`, a neighbour here)."""

    @property
    def radiance_table(self) -> tuple[float, float, np.ndarray]:
        """The band's Planck table.

        Returns
        -------
        t_min_k, t_step_k : float
            The table's first BT and its step, K.
        table : numpy.ndarray
            Band radiance per BT, mW/(m2 sr cm-1).
        """
        ...


# the passes' threads take scans one at a time as they come free, not in equal shares fixed in advance:
# the read-ahead thread takes turns on the cores, and a share fixed in advance waits for the slowest
SCANS_PER_TASK = 1


@dataclass
class SwathPiece:
    """One VIIRS granule (scans of *detectors* rows: 32 on the I grid, 16 on the M) ready for collocation.

    ecef_m (rows, cols, 3) float32 (0.5 m resolution) of the 3-D pixel points; radiance (rows, cols) the
    pixels' I5 band radiance mW/(m2 sr cm-1), NaN where unusable; *rendered* (views, rows, cols), when the
    pixels stand at a height, the radiance a CrIS ray at each in-track SBF angle of *view_alpha_rad* sees on
    its way to each GEO point (:func:`swath_piece`), NaN where the pixel is unusable; area_vec_m2
    (rows, cols, 3) float32 the vector footprint with scan overlap removed. block_centre_m (rows/4,
    ceil(cols/4), 3) and block_radius_m bound the usable pixels of each 4 x 4 block (NaN where it has none).
    Per column: the smallest column spacing within +-200 columns (col_spacing_m), the along-track advance of a
    scan (advance_m) and the detector step (det_step_m), all m; max_height_m the highest usable pixel. They
    size the search windows. The piece holds the granule's columns from *first_column* on that are seen within
    *view_rad* of nadir (inf: all columns), and its scans from *first_scan* on that cover the IET span
    *span_us* (start of the first scan, start of the scan after the last; -inf and inf at the granule's ends).
    """

    ecef_m: np.ndarray
    radiance: np.ndarray
    area_vec_m2: np.ndarray
    block_centre_m: np.ndarray
    block_radius_m: np.ndarray
    col_spacing_m: np.ndarray
    advance_m: np.ndarray
    det_step_m: np.ndarray
    max_height_m: float
    tree: cKDTree
    tree_rows: np.ndarray
    tree_cols: np.ndarray
    first_column: int = 0
    view_rad: float = math.inf
    first_scan: int = 0
    span_us: tuple = (-math.inf, math.inf)
    rendered: np.ndarray | None = None
    view_alpha_rad: np.ndarray = field(default_factory=lambda: np.zeros(0))
    detectors: int = VIIRS_DETECTORS

    @property
    def shape(self) -> tuple[int, int]:
        """The rows and columns of the prepared piece.

        Returns
        -------
        tuple of int
            (rows, cols).
        """
        rows, cols = self.radiance.shape
        return rows, cols

    def covers(self, t0_us: float, t1_us: float) -> bool:
        """Whether the piece holds every scan observed between two times.

        Parameters
        ----------
        t0_us, t1_us : float
            The span, IET us.

        Returns
        -------
        bool
            True when every scan of the span is prepared.
        """
        return self.span_us[0] <= t0_us and t1_us < self.span_us[1]

    def nearest(self, points_m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The first pixel of the usable block whose centre lies nearest each point, and that distance.

        Parameters
        ----------
        points_m : numpy.ndarray
            ECEF points, m, shape (N, 3).

        Returns
        -------
        row, col : numpy.ndarray
            The pixel, shape (N,).
        distance_m : numpy.ndarray
            The distance to the block's centre, m.
        """
        dist, idx = self.tree.query(points_m)
        return self.tree_rows[idx], self.tree_cols[idx], dist


@dataclass
class ViirsSwath:
    """The prepared granules (consecutive or not) that a CrIS granule's cones may reach.

    Pieces are never stacked: cone sums add over pixels, so each piece is searched on its own.
    """

    pieces: list


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _ecef(lat: np.ndarray, lon: np.ndarray, h: np.ndarray, out: np.ndarray) -> None:
    """WGS84 geodetic (rad, rad, m; float32 arrays) to ECEF float32 *out* (..., 3): `.geodesy.ecef_m`."""
    rows, cols = lat.shape
    for r in range(rows):
        for c in range(cols):
            out[r, c, 0], out[r, c, 1], out[r, c, 2] = ecef_m(
                np.float64(lat[r, c]), np.float64(lon[r, c]), np.float64(h[r, c])
            )


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _scan_ends(scan: np.ndarray, first: np.ndarray, last: np.ndarray, step: np.ndarray) -> None:
    """First and last valid detector positions (float64 (cols, 3), NaN where the column has none) of one
    scan (detectors, cols, 3) and the detector step between them (m)."""
    for c in range(scan.shape[1]):
        i0 = -1
        i1 = -1
        for d in range(scan.shape[0]):
            if math.isfinite(scan[d, c, 0]):
                if i0 < 0:
                    i0 = d
                i1 = d
        if i0 < 0:
            first[c, :] = np.nan
            last[c, :] = np.nan
            step[c] = np.nan
            continue
        s2 = 0.0
        for x in range(3):
            first[c, x] = scan[i0, c, x]
            last[c, x] = scan[i1, c, x]
            s2 += (last[c, x] - first[c, x]) ** 2
        step[c] = math.sqrt(s2) / max(i1 - i0, 1)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _locate_scan(
    k: int,
    det: int,
    lat: np.ndarray,
    lon: np.ndarray,
    h: np.ndarray,
    bt: np.ndarray,
    good: np.ndarray,
    table: np.ndarray,
    t_min_k: float,
    t_step_k: float,
    pos: np.ndarray,
    radiance: np.ndarray,
    first: np.ndarray,
    last: np.ndarray,
    step: np.ndarray,
) -> None:
    """Pass 1 for scan k (of *det* detectors): pixel points, band radiance from BT (linear in the uniform BT
    table, NaN outside it or where not *good*), and the scan's ends (slot k + 1; 0 and nscan + 1 are the
    halos)."""
    cols = lat.shape[1]
    sl = slice(k * det, (k + 1) * det)
    _ecef(lat[sl], lon[sl], h[sl], pos[sl])
    for r in range(k * det, (k + 1) * det):
        for c in range(cols):
            radiance[r, c] = _band_radiance(bt[r, c], table, t_min_k, t_step_k) if good[r, c] else np.nan
    _scan_ends(pos[sl], first[k + 1], last[k + 1], step[k + 1])


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _band_radiance(bt_k: float, table: np.ndarray, t_min_k: float, t_step_k: float) -> float:
    """The band radiance of *bt_k*: linear in the uniform BT table (its first BT *t_min_k*, its step
    *t_step_k*), NaN outside it or for NaN."""
    nt = table.shape[0]
    x = (np.float64(bt_k) - t_min_k) / t_step_k
    if x >= 0.0 and x <= nt - 1:
        i = min(int(x), nt - 2)
        w = x - i
        return table[i] * (1.0 - w) + table[i + 1] * w
    return np.nan


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _views_radiance(
    seen_bt_k: np.ndarray,
    own: np.ndarray,
    table: np.ndarray,
    t_min_k: float,
    t_step_k: float,
    out: np.ndarray,
) -> None:
    """The band radiance (:func:`_band_radiance`) of the rendered views *seen_bt_k* (views, rows, cols)
    into *out*, NaN where the pixel's own radiance *own* (rows, cols) is; rows in parallel."""
    for r in numba.prange(seen_bt_k.shape[1]):
        for v in range(seen_bt_k.shape[0]):
            for c in range(seen_bt_k.shape[2]):
                ok = math.isfinite(own[r, c])
                out[v, r, c] = _band_radiance(seen_bt_k[v, r, c], table, t_min_k, t_step_k) if ok else np.nan


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _locate(
    det: int,
    lat: np.ndarray,
    lon: np.ndarray,
    h: np.ndarray,
    bt: np.ndarray,
    good: np.ndarray,
    table: np.ndarray,
    t_min_k: float,
    t_step_k: float,
    pos: np.ndarray,
    radiance: np.ndarray,
    first: np.ndarray,
    last: np.ndarray,
    step: np.ndarray,
) -> None:
    """Pass 1 (:func:`_locate_scan`), scans in parallel."""
    for k in numba.prange(lat.shape[0] // det):
        _locate_scan(
            k, det, lat, lon, h, bt, good, table, t_min_k, t_step_k, pos, radiance, first, last, step
        )


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _centred(here: float, nxt: float, prv: float) -> float:
    """Half the difference of a pixel's two neighbours *nxt* and *prv* (one coordinate, m), one-sided
    where one is missing (NaN)."""
    fwd = nxt - here
    bwd = here - prv
    both = (fwd + bwd) * 0.5
    return both if math.isfinite(both) else (fwd if math.isfinite(fwd) else bwd)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _scan_frame(
    first: np.ndarray, last: np.ndarray, step: np.ndarray, have: np.ndarray, k: int, c: int, out: np.ndarray
) -> None:
    """The along-track frame of column c of scan slot k, for :func:`_share`: the unit vector u from its
    first to its last valid detector, u . first, half a detector step, and the spans along u (plus half
    a step each side) of the neighbouring scans' columns, (+inf, -inf) where there is none."""
    u0 = last[k, c, 0] - first[k, c, 0]
    u1 = last[k, c, 1] - first[k, c, 1]
    u2 = last[k, c, 2] - first[k, c, 2]
    norm = math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    u0, u1, u2 = u0 / norm, u1 / norm, u2 / norm
    out[0], out[1], out[2] = u0, u1, u2
    out[3] = first[k, c, 0] * u0 + first[k, c, 1] * u1 + first[k, c, 2] * u2
    out[4] = step[k, c] / 2
    for slot, n in ((5, k - 1), (7, k + 1)):
        if have[n] and math.isfinite(step[n, c]):
            lo = first[n, c, 0] * u0 + first[n, c, 1] * u1 + first[n, c, 2] * u2 - out[3]
            hi = last[n, c, 0] * u0 + last[n, c, 1] * u1 + last[n, c, 2] * u2 - out[3]
            out[slot], out[slot + 1] = lo - step[n, c] / 2, hi + step[n, c] / 2
        else:
            out[slot], out[slot + 1] = np.inf, -np.inf


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _share(p0: float, p1: float, p2: float, frames: np.ndarray, c: int) -> float:
    """The share (0.5..1) of the footprint of the pixel at (p0, p1, p2) (ECEF m) in column c that is its
    own, in its column's frame (frames[:, c], :func:`_scan_frame`).

    Along the track each pixel spans one detector step centred on it, each neighbouring scan its
    first-to-last valid detector span plus half a step each side; an overlap of a fraction f of the
    footprint leaves the pixel 1 - f / 2. (Counting whole pixels in or out instead leaves ~1 % too much
    weight in stripes at the scan edges near nadir, where the overlap is a fraction of a detector, and
    biases the in-track minimum there.) A neighbour with no valid pixel in the column overlaps nothing.
    """
    s_pix = p0 * frames[0, c] + p1 * frames[1, c] + p2 * frames[2, c] - frames[3, c]
    half = frames[4, c]
    before = min(s_pix + half, frames[6, c]) - max(s_pix - half, frames[5, c])
    after = min(s_pix + half, frames[8, c]) - max(s_pix - half, frames[7, c])
    return 1.0 - min(max(before / (2 * half), 0.0), 1.0) / 2 - min(max(after / (2 * half), 0.0), 1.0) / 2


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _load_row(pos: np.ndarray, r: int, inside: bool, out: np.ndarray) -> None:
    """Row r of *pos* (cols, 3) into out (3, cols + 2) as float64, one coordinate per line, with a NaN
    column at each end; all NaN when the row is not *inside* the scan."""
    if not inside:
        out[:] = np.nan
        return
    out[:, 0] = np.nan
    out[:, -1] = np.nan
    for c in range(pos.shape[1]):
        for x in range(3):
            out[x, c + 1] = pos[r, c, x]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _weigh_scan(
    k: int,
    det: int,
    pos: np.ndarray,
    h: np.ndarray,
    radiance: np.ndarray,
    first: np.ndarray,
    last: np.ndarray,
    step: np.ndarray,
    have: np.ndarray,
    area: np.ndarray,
    centre: np.ndarray,
    radius: np.ndarray,
    top: np.ndarray,
) -> None:
    """Pass 2 for scan k (of *det* detectors): vector footprints with the scan overlap removed (into *area*),
    radiance NaN where either is unusable, the bounding sphere (centre, radius + 1 m for the float32
    rounding) of each block's usable pixels (NaN where it has none), and the height of the scan's highest
    usable pixel (top[k], m).

    Each footprint is the cross product of half the differences of the pixel's neighbours along the scan
    and across the detectors; the rows it needs are held as float64 lines of coordinates padded with NaN
    (a missing neighbour), so that the loop over a row's pixels has no branches and vectorises.
    """
    cols = radiance.shape[1]
    nbc = centre.shape[1]
    frames = np.empty((9, cols))
    for c in range(cols):
        _scan_frame(first, last, step, have, k + 1, c, frames[:, c])
    prev, here, after = np.empty((3, cols + 2)), np.empty((3, cols + 2)), np.empty((3, cols + 2))
    foot = np.empty((3, cols))
    lo = np.empty((nbc, 3))  # the bounding box of each block of the current band of BLOCK_PX rows
    hi = np.empty((nbc, 3))
    for r in range(k * det, (k + 1) * det):
        d = r - k * det
        _load_row(pos, r - 1, d > 0, prev)
        _load_row(pos, r, True, here)
        _load_row(pos, r + 1, d + 1 < det, after)
        if d % BLOCK_PX == 0:
            lo[:] = np.inf
            hi[:] = -np.inf
        for c in range(cols):
            p0, p1, p2 = here[0, c + 1], here[1, c + 1], here[2, c + 1]
            a0 = _centred(p0, here[0, c + 2], here[0, c])
            a1 = _centred(p1, here[1, c + 2], here[1, c])
            a2 = _centred(p2, here[2, c + 2], here[2, c])
            b0 = _centred(p0, after[0, c + 1], prev[0, c + 1])
            b1 = _centred(p1, after[1, c + 1], prev[1, c + 1])
            b2 = _centred(p2, after[2, c + 1], prev[2, c + 1])
            s = _share(p0, p1, p2, frames, c)
            foot[0, c] = (a1 * b2 - a2 * b1) * s
            foot[1, c] = (a2 * b0 - a0 * b2) * s
            foot[2, c] = (a0 * b1 - a1 * b0) * s
        for c in range(cols):
            x0, x1, x2 = foot[0, c], foot[1, c], foot[2, c]
            area[r, c, 0], area[r, c, 1], area[r, c, 2] = x0, x1, x2
            if not (math.isfinite(x0) and math.isfinite(x1) and math.isfinite(x2)):
                radiance[r, c] = np.nan
            if math.isfinite(radiance[r, c]):
                top[k] = max(top[k], h[r, c])
                bc = c // BLOCK_PX
                for x in range(3):
                    lo[bc, x] = min(lo[bc, x], pos[r, c, x])
                    hi[bc, x] = max(hi[bc, x], pos[r, c, x])
        if d % BLOCK_PX == BLOCK_PX - 1:
            br = r // BLOCK_PX
            for bc in range(nbc):
                if lo[bc, 0] > hi[bc, 0]:
                    centre[br, bc, :] = np.nan
                    radius[br, bc] = np.nan
                    continue
                lo0, lo1, lo2 = lo[bc, 0], lo[bc, 1], lo[bc, 2]
                hi0, hi1, hi2 = hi[bc, 0], hi[bc, 1], hi[bc, 2]
                centre[br, bc, 0] = (lo0 + hi0) / 2
                centre[br, bc, 1] = (lo1 + hi1) / 2
                centre[br, bc, 2] = (lo2 + hi2) / 2
                radius[br, bc] = math.sqrt((hi0 - lo0) ** 2 + (hi1 - lo1) ** 2 + (hi2 - lo2) ** 2) / 2 + 1.0


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _weigh(
    det: int,
    pos: np.ndarray,
    h: np.ndarray,
    radiance: np.ndarray,
    first: np.ndarray,
    last: np.ndarray,
    step: np.ndarray,
    have: np.ndarray,
    area: np.ndarray,
    centre: np.ndarray,
    radius: np.ndarray,
    top: np.ndarray,
) -> None:
    """Pass 2 (:func:`_weigh_scan`), scans in parallel."""
    for k in numba.prange(radiance.shape[0] // det):
        _weigh_scan(k, det, pos, h, radiance, first, last, step, have, area, centre, radius, top)


def swath_piece(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    bt_k: np.ndarray,
    good: np.ndarray,
    band: BandTable,
    before: tuple[np.ndarray, ...] | None = None,
    after: tuple[np.ndarray, ...] | None = None,
    sat_m: np.ndarray | None = None,
    view_rad: float = math.inf,
    scan_start_us: np.ndarray | None = None,
    span_us: tuple[float, float] | None = None,
    seen_bt_k: np.ndarray | None = None,
    view_alpha_rad: np.ndarray | None = None,
    detectors: int = VIIRS_DETECTORS,
) -> SwathPiece:
    """Prepare one VIIRS granule's geolocation and I5 BT for collocation.

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    bt_k : numpy.ndarray
        The pixels' band BT, K, shape (rows, cols).
    good : numpy.ndarray
        Where a pixel is usable.
    band : BandTable
        The I5 band (:class:`monitor.instrument.spectral.BandModel`): pixel BT to band radiance.
    before, after : tuple of numpy.ndarray, optional
        (lat_rad, lon_rad, height_m) of the neighbouring granules' adjacent scan, so that the scan overlap at
        the granule's first and last scan is counted as inside a continuous swath.
    sat_m : numpy.ndarray, optional
        Each scan's spacecraft position, ECEF, m, shape (nscan, 3): only the columns seen within *view_rad* of
        nadir are then prepared (:func:`reach.view_columns`).
    view_rad : float, optional
        The view angle from nadir beyond which no cone reaches, rad.
    scan_start_us : numpy.ndarray, optional
        Each scan's start time, IET us.
    span_us : tuple of float, optional
        With *scan_start_us*, only the scans observed in (t0, t1), IET us, are prepared
        (:func:`reach.scans_between`), each with the same weights as in the whole granule.
    seen_bt_k : numpy.ndarray, optional
        The BT a CrIS ray at each angle of *view_alpha_rad* sees on its way to each GEO point (clouds with
        height: :func:`monitor.collocation.render.rendered_bt`), K, shape (views, rows, cols).
    view_alpha_rad : numpy.ndarray, optional
        The in-track SBF angles of *seen_bt_k*, rad, shape (views,).
    detectors : int, optional
        The rows of a scan: the grid's detectors (:data:`monitor.core.bands.GRIDS`).

    Returns
    -------
    SwathPiece
        The 3-D pixel points, their band radiance and solid-angle weights (module docstring), and the
        rendered views' radiance when given.
    """
    det = detectors
    scans, kept = kept_pixels(lat_rad, lon_rad, height_m, sat_m, view_rad, scan_start_us, span_us, det)
    if scans != slice(None) and scan_start_us is not None:
        first, stop, _ = scans.indices(len(scan_start_us))
        r0, r1 = first * det, stop * det
        geo = (lat_rad, lon_rad, height_m)
        if first > 0:
            before = tuple(a[r0 - det : r0] for a in geo)
        if r1 < np.shape(lat_rad)[0]:
            after = tuple(a[r1 : r1 + det] for a in geo)
        lat_rad, lon_rad, height_m, bt_k, good = (a[r0:r1] for a in (*geo, bt_k, good))
        seen_bt_k = None if seen_bt_k is None else seen_bt_k[:, r0:r1]
        sat_m = None if sat_m is None else sat_m[first:stop]
        t = np.asarray(scan_start_us, np.int64)
        covered_us = (t[first] if first > 0 else -math.inf, t[stop] if stop < len(t) else math.inf)
    else:
        covered_us = (-math.inf, math.inf)
    if sat_m is not None and view_rad < math.pi / 2:
        lat_rad, lon_rad, height_m = lat_rad[:, kept], lon_rad[:, kept], height_m[:, kept]
        bt_k, good = bt_k[:, kept], good[:, kept]
        seen_bt_k = None if seen_bt_k is None else seen_bt_k[:, :, kept]
        before, after = (None if b is None else tuple(a[..., kept] for a in b) for b in (before, after))
    else:
        view_rad = math.inf
    f32 = np.float32
    # the kernels read the kept columns in place (a copy of them costs more than the strided reads)
    lat, lon, h = (np.asarray(a, f32) for a in (lat_rad, lon_rad, height_m))
    rows, cols = lat.shape
    nscan = rows // det
    pos = np.empty((rows, cols, 3), f32)
    radiance = np.empty((rows, cols), f32)
    ends_first = np.full((nscan + 2, cols, 3), np.nan)  # each scan's first and last row
    ends_last = np.full_like(ends_first, np.nan)
    step = np.full((nscan + 2, cols), np.nan)
    have = np.zeros(nscan + 2, bool)
    have[1:-1] = True
    t_min, t_step, table = band.radiance_table
    bt, good = np.asarray(bt_k, f32), np.asarray(good, bool)
    with KERNEL_LOCK, numba.parallel_chunksize(SCANS_PER_TASK):
        _locate(det, lat, lon, h, bt, good, table, t_min, t_step, pos, radiance, ends_first, ends_last, step)
    for slot, halo in ((0, before), (nscan + 1, after)):
        if halo is not None:
            hp = np.empty(np.shape(halo[0]) + (3,), f32)
            _ecef(*(np.ascontiguousarray(a, f32) for a in halo), hp)
            _scan_ends(hp, ends_first[slot], ends_last[slot], step[slot])
            have[slot] = True
    area = np.empty((rows, cols, 3), f32)
    centre = np.empty((rows // BLOCK_PX, -(-cols // BLOCK_PX), 3))
    radius = np.empty(centre.shape[:2])
    top = np.zeros(nscan)  # the highest usable pixel of each scan, m (0: none above the ellipsoid)
    with KERNEL_LOCK, numba.parallel_chunksize(SCANS_PER_TASK):
        _weigh(det, pos, h, radiance, ends_first, ends_last, step, have, area, centre, radius, top)
    views, angles = None, np.zeros(0)
    if seen_bt_k is not None and view_alpha_rad is not None:
        angles = np.asarray(view_alpha_rad, np.float64)
        views = np.empty((len(angles), rows, cols), f32)
        with KERNEL_LOCK:
            _views_radiance(seen_bt_k, radiance, table, t_min, t_step, views)

    col_spacing, advance, det_step = search_spacings(pos, det)
    r_idx, c_idx = np.nonzero(np.isfinite(radius))
    # unbalanced with large leaves: the same nearest blocks, a faster build (studies/rows/, the speed record)
    tree = cKDTree(centre[r_idx, c_idx], leafsize=64, balanced_tree=False, compact_nodes=False)
    return SwathPiece(
        pos,
        radiance,
        area,
        centre,
        radius,
        col_spacing,
        advance,
        det_step,
        max(float(top.max()), 0.0),
        tree,
        r_idx * BLOCK_PX,
        c_idx * BLOCK_PX,
        kept.start or 0,
        view_rad,
        scans.start or 0,
        covered_us,
        views,
        angles,
        det,
    )
