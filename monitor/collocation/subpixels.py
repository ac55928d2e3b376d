"""A VIIRS grid's pixels split into n x n sub-pixels, for the cone test on a coarse grid.

The cone collocation (Wang et al. 2016) counts a pixel in a perturbed cone when its centre lies inside: a
pixel on the edge is in or out whole. As the LOS is perturbed, the edge crosses pixel centres and the cone's
mean jumps by what one pixel holds. An M-grid pixel is twice as wide as an I-grid one and a cone holds a
quarter as many, so the jumps are larger, and where the scene leaves the cost shallow the minimum moves with
them (studies/second-band.md). Split into n x n sub-pixels, each holding its pixel's value and geolocated
between its neighbours, the edge moves in steps of 1/n pixel: at n = 2 the M grid's cones are drawn at the I
grid's pitch, while what they average is still the M band's pixels.

Sub-pixel k of n along an axis stands (k + 1/2)/n - 1/2 of a pixel from its pixel's centre, on the local
slope of the geolocation: the centred difference of the two neighbours, or the one-sided difference where a
neighbour is missing (a bow-tie deleted row, the edge of a scan or a granule). Rows are split within their
scan: a scan's detectors are one sweep, and the next scan's first row overlaps this one's last (the bow-tie)
instead of following it.
"""

from __future__ import annotations

import numpy as np


def _wrapped(angle_rad: np.ndarray) -> np.ndarray:
    """Angles, rad, into [-pi, pi)."""
    return (angle_rad + np.pi) % (2 * np.pi) - np.pi


def _slope(a: np.ndarray, axis: int, angle: bool) -> np.ndarray:
    """The change per pixel along *axis*: centred, one-sided where a neighbour is missing (NaN); for an
    *angle* (longitude), each difference the short way round the antimeridian."""
    d = np.diff(a, axis=axis)
    if angle:
        d = _wrapped(d)
    pad = [(0, 0)] * a.ndim
    pad[axis] = (1, 0)
    backward = np.pad(d, pad, constant_values=np.nan)
    pad[axis] = (0, 1)
    forward = np.pad(d, pad, constant_values=np.nan)
    centred = 0.5 * (backward + forward)
    return np.where(np.isnan(backward), forward, np.where(np.isnan(forward), backward, centred))


def _spread(a: np.ndarray, slope: np.ndarray, n: int, axis: int) -> np.ndarray:
    """Each pixel's n sub-pixels along *axis*, interleaved: a + ((k + 1/2)/n - 1/2) slope, k = 0..n-1."""
    shifts = (np.arange(n) + 0.5) / n - 0.5
    parts = np.stack([a + s * slope for s in shifts], axis=axis + 1)
    shape = list(a.shape)
    shape[axis] *= n
    return parts.reshape(shape)


def split_field(a: np.ndarray, detectors: int, n: int, angle: bool = False) -> np.ndarray:
    """A geolocation field at its sub-pixels, each scan split on its own.

    Parameters
    ----------
    a : numpy.ndarray
        The field (latitude or longitude, rad; height, m), shape (rows, cols) of scans of *detectors* rows;
        NaN where a pixel has none.
    detectors : int
        The rows of a scan.
    n : int
        Sub-pixels per pixel along each axis.
    angle : bool, optional
        The field is a longitude: slopes are taken the short way round, values kept in [-pi, pi).

    Returns
    -------
    numpy.ndarray
        Shape (rows * n, cols * n), the float type of *a* (computed in float64); NaN where the pixel is NaN,
        or has no neighbour along an axis.
    """
    a = np.asarray(a)
    rows, cols = a.shape
    scans = a.astype(np.float64).reshape(rows // detectors, detectors, cols)
    for axis in (1, 2):
        scans = _spread(scans, _slope(scans, axis, angle), n, axis)
    out = scans.reshape(rows * n, cols * n)
    return (_wrapped(out) if angle else out).astype(np.result_type(a.dtype, np.float32))


def split_values(a: np.ndarray, n: int) -> np.ndarray:
    """A pixel field (BT, quality flags) at the sub-pixels: each holds its pixel's value.

    Parameters
    ----------
    a : numpy.ndarray
        The field, shape (rows, cols).
    n : int
        Sub-pixels per pixel along each axis.

    Returns
    -------
    numpy.ndarray
        Shape (rows * n, cols * n), the dtype of *a*.
    """
    return np.repeat(np.repeat(a, n, axis=0), n, axis=1)


def split_geolocation(
    lat_rad: np.ndarray, lon_rad: np.ndarray, height_m: np.ndarray, detectors: int, n: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodetic latitude, longitude and height at the sub-pixels (:func:`split_field`).

    Parameters
    ----------
    lat_rad, lon_rad : numpy.ndarray
        Geodetic latitude and longitude, rad, shape (rows, cols) of scans of *detectors* rows.
    height_m : numpy.ndarray
        Height above the ellipsoid, m, the same shape.
    detectors : int
        The rows of a scan.
    n : int
        Sub-pixels per pixel along each axis.

    Returns
    -------
    lat_rad, lon_rad, height_m : numpy.ndarray
        rad, rad (in [-pi, pi)), m, shape (rows * n, cols * n).
    """
    return (
        split_field(lat_rad, detectors, n),
        split_field(lon_rad, detectors, n, angle=True),
        split_field(height_m, detectors, n),
    )
