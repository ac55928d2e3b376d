"""Which pixels of a VIIRS granule a CrIS granule can reach: the scans observed in its time span and the
columns seen within its view angle of nadir; and the spacings that size the search around a FOV.

A CrIS granule (32 s) needs about a third of one VIIRS granule's scans and, within the CrIS swath's
+-48.3 deg, not the VIIRS columns beyond it: :mod:`monitor.collocation.swath` prepares only these, with
the same weights as in the whole granule, so that a piece collocates as the whole would.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.ndimage import minimum_filter1d

from monitor.core.constants import VIIRS_DETECTORS
from monitor.geometry import wgs84

SPACING_WINDOW_COLS = 401  # the column spacing used around a column is the smallest within +-200 columns
BLOCK_PX = 4  # pixels are searched in BLOCK_PX x BLOCK_PX blocks (a divisor of either grid's detectors)


def view_columns(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    sat_m: np.ndarray,
    view_rad: float,
    detectors: int = VIIRS_DETECTORS,
) -> slice:
    """The columns holding every pixel seen within *view_rad* of nadir.

    Judged on the middle detector row of every fourth scan and the last, from that scan's spacecraft: a
    column's view angle changes little from scan to scan. The slice starts on a block boundary, so that the
    search blocks, and the order in which the cone sums add pixels, are those of the whole granule.

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    sat_m : numpy.ndarray
        Each scan's spacecraft position, ECEF, m, shape (nscan, 3); NaN ignored.
    view_rad : float
        The view angle from the geocentric nadir, rad.
    detectors : int, optional
        The rows of a scan (the grid's detectors).

    Returns
    -------
    slice
        The columns, starting on a search block's boundary; all when no pixel qualifies.
    """
    scans = np.unique(np.r_[np.arange(0, len(sat_m), 4), len(sat_m) - 1])
    sat = np.asarray(sat_m, float)[scans]
    mid = scans * detectors + detectors // 2
    los = wgs84.geodetic_to_ecef(lat_rad[mid], lon_rad[mid], height_m[mid]) - sat[:, None, :]
    nadir = -sat / np.linalg.norm(sat, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore"):
        seen = np.sum(los * nadir[:, None, :], -1) >= np.cos(view_rad) * np.linalg.norm(los, axis=-1)
    cols = np.flatnonzero(seen.any(axis=0))
    return slice(int(cols[0]) // BLOCK_PX * BLOCK_PX, int(cols[-1]) + 1) if cols.size else slice(None)


def scans_between(scan_start_us: ArrayLike, t0_us: float, t1_us: float) -> slice:
    """The scans observed between two times.

    Parameters
    ----------
    scan_start_us : array_like
        Each scan's start time, IET us; a scan lasts until the next starts, the last to the granule's end.
    t0_us, t1_us : float
        The span, IET us.

    Returns
    -------
    slice
        The scans; all when the start times are not all set and increasing (nothing to judge by).
    """
    t = np.asarray(scan_start_us, np.int64)
    if t.size == 0 or t[0] <= 0 or np.any(np.diff(t) <= 0):
        return slice(None)
    first = max(int(np.searchsorted(t, t0_us, side="right")) - 1, 0)
    stop = int(np.searchsorted(t, t1_us, side="right"))
    return slice(first, max(stop, first + 1))


def kept_pixels(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    height_m: np.ndarray,
    sat_m: np.ndarray | None = None,
    view_rad: float = math.inf,
    scan_start_us: np.ndarray | None = None,
    span_us: tuple[float, float] | None = None,
    detectors: int = VIIRS_DETECTORS,
) -> tuple[slice, slice]:
    """The scans and the columns of a granule that :func:`monitor.collocation.swath.swath_piece` keeps.

    Parameters
    ----------
    lat_rad, lon_rad, height_m : numpy.ndarray
        The granule's GEO: geodetic latitude and longitude (rad) and height above the ellipsoid (m), shape
        (rows, cols) of scans of *detectors* rows.
    sat_m : numpy.ndarray, optional
        Each scan's spacecraft position, ECEF, m, shape (nscan, 3).
    view_rad : float, optional
        The view angle from nadir beyond which no cone reaches, rad.
    scan_start_us : numpy.ndarray, optional
        Each scan's start time, IET us.
    span_us : tuple of float, optional
        The span (t0, t1) the CrIS granules reach, IET us.
    detectors : int, optional
        The rows of a scan (the grid's detectors).

    Returns
    -------
    scans, columns : slice
        The scans observed within *span_us* (:func:`scans_between`) and the columns seen within *view_rad* on
        them (:func:`view_columns`); all of either where there is nothing to judge it by.
    """
    scans = slice(None)
    if scan_start_us is not None and span_us is not None:
        scans = scans_between(scan_start_us, *span_us)
    columns = slice(None)
    if sat_m is not None and view_rad < math.pi / 2:
        first, stop, _ = scans.indices(np.shape(lat_rad)[0] // detectors)
        r = slice(first * detectors, stop * detectors)
        sat = np.asarray(sat_m)[first:stop]
        columns = view_columns(lat_rad[r], lon_rad[r], height_m[r], sat, view_rad, detectors)
    return scans, columns


def _np_half_diff(p: np.ndarray, axis: int) -> np.ndarray:
    """Half the difference of the two neighbours along *axis* (numpy), one-sided where one is missing."""
    fwd = np.full_like(p, np.nan)
    bwd = np.full_like(p, np.nan)
    n = p.shape[axis]
    a, b = [slice(None)] * p.ndim, [slice(None)] * p.ndim
    a[axis], b[axis] = slice(0, n - 1), slice(1, n)
    np.subtract(p[tuple(b)], p[tuple(a)], out=fwd[tuple(a)])
    bwd[tuple(b)] = fwd[tuple(a)]
    both = (fwd + bwd) * 0.5
    return np.where(np.isfinite(both), both, np.where(np.isfinite(fwd), fwd, bwd))


def _fill_nan(a: ArrayLike) -> np.ndarray:
    a = np.asarray(a, float)
    ok = np.isfinite(a)
    return np.interp(np.arange(len(a)), np.nonzero(ok)[0], a[ok]) if not ok.all() else a


def search_spacings(pos_m: np.ndarray, detectors: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """What sizes a prepared granule's search windows, per column, from its middle scan.

    Parameters
    ----------
    pos_m : numpy.ndarray
        The pixels' 3-D points, ECEF, m, shape (rows, cols, 3) of scans of *detectors* rows.
    detectors : int
        The rows of a scan.

    Returns
    -------
    col_spacing_m : numpy.ndarray
        The smallest column spacing within +-200 columns (:data:`SPACING_WINDOW_COLS`), m.
    advance_m : numpy.ndarray
        The along-track advance of a scan, m (the detectors' span with one scan).
    det_step_m : numpy.ndarray
        The detector step, m.
    """
    rows, cols, _ = pos_m.shape
    nscan = rows // detectors
    scan = pos_m.reshape(nscan, detectors, cols, 3)
    mid = scan[nscan // 2]
    col_spacing = _fill_nan(np.nanmedian(np.linalg.norm(_np_half_diff(mid, axis=1), axis=-1), axis=0))
    det_step = np.nanmedian(np.linalg.norm(_np_half_diff(mid, axis=0), axis=-1), axis=0)
    if nscan > 1:
        advance = np.nanmedian(np.linalg.norm(scan[nscan // 2] - scan[nscan // 2 - 1], axis=-1), axis=0)
    else:
        advance = det_step * detectors
    spacing = minimum_filter1d(col_spacing, SPACING_WINDOW_COLS, mode="nearest")
    return spacing, _fill_nan(advance), _fill_nan(det_step)
