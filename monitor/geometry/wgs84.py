"""The WGS84 ellipsoid: geodetic <-> ECEF, the local ENU basis, and ray-ellipsoid intersection.

All positions are Earth-centred Earth-fixed (ECEF) in metres; latitudes and longitudes are geodetic,
in radians.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

A_M = 6378137.0  # WGS84 equatorial radius
F = 1.0 / 298.257223563  # WGS84 flattening
B_M = A_M * (1.0 - F)  # polar radius
E2 = F * (2.0 - F)  # first eccentricity squared
OMEGA_EARTH_RAD_S = 7.2921151467e-5  # WGS84 Earth rotation rate
GM_M3_S2 = 3.986004418e14  # WGS84 gravitational parameter
J2 = 1.08262668e-3  # EGM96 second zonal harmonic


def geodetic_to_ecef(lat_rad: ArrayLike, lon_rad: ArrayLike, h_m: ArrayLike = 0.0) -> np.ndarray:
    """The ECEF position of geodetic coordinates.

    Parameters
    ----------
    lat_rad, lon_rad : array_like
        Geodetic latitude and longitude, rad.
    h_m : array_like, optional
        Height above the WGS84 ellipsoid, m.

    Returns
    -------
    numpy.ndarray
        ECEF positions, m, shape (..., 3).
    """
    lat, lon, h = np.broadcast_arrays(
        np.asarray(lat_rad, float), np.asarray(lon_rad, float), np.asarray(h_m, float)
    )
    sin_lat = np.sin(lat)
    n = A_M / np.sqrt(1.0 - E2 * sin_lat**2)
    r = (n + h) * np.cos(lat)  # distance from the polar axis
    out = np.empty(lat.shape + (3,))
    np.multiply(r, np.cos(lon), out=out[..., 0])
    np.multiply(r, np.sin(lon), out=out[..., 1])
    np.multiply(n * (1.0 - E2) + h, sin_lat, out=out[..., 2])
    return out


def ecef_to_geodetic(xyz_m: ArrayLike, iterations: int = 5) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodetic coordinates of ECEF points, by Bowring's iteration converged to < 1 mm.

    Parameters
    ----------
    xyz_m : array_like
        ECEF points, m, shape (..., 3).
    iterations : int, optional
        Bowring's iterations: 5 hold from the ground to orbit, 2 within ~10 km of the ellipsoid.

    Returns
    -------
    lat_rad, lon_rad, h_m : numpy.ndarray
        Geodetic latitude and longitude (rad) and height above the ellipsoid (m).
    """
    xyz = np.asarray(xyz_m, float)
    x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    lon = np.arctan2(y, x)
    p = np.hypot(x, y)
    lat = np.arctan2(z, p * (1.0 - E2))
    for _ in range(iterations):
        sin_lat = np.sin(lat)
        n = A_M / np.sqrt(1.0 - E2 * sin_lat**2)
        h = p * np.cos(lat) + z * sin_lat - A_M**2 / n
        lat = np.arctan2(z, p * (1.0 - E2 * n / (n + h)))
    sin_lat = np.sin(lat)
    n = A_M / np.sqrt(1.0 - E2 * sin_lat**2)
    h = p * np.cos(lat) + z * sin_lat - A_M**2 / n
    return lat, lon, h


def surface_to_geodetic(xyz_m: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Geodetic latitude and longitude of ECEF points on the ellipsoid (h = 0), closed-form.

    tan(lat) = z / ((1 - e^2) p), p = sqrt(x^2 + y^2): no iteration.

    Parameters
    ----------
    xyz_m : array_like
        ECEF points on the ellipsoid, m, shape (..., 3).

    Returns
    -------
    lat_rad, lon_rad : numpy.ndarray
        Geodetic latitude and longitude, rad.
    """
    xyz = np.asarray(xyz_m, float)
    x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
    return np.arctan2(z, np.hypot(x, y) * (1.0 - E2)), np.arctan2(y, x)


def enu_basis(lat_rad: ArrayLike, lon_rad: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit vectors east, north and up at geodetic coordinates.

    Parameters
    ----------
    lat_rad, lon_rad : array_like
        Geodetic latitude and longitude, rad.

    Returns
    -------
    east, north, up : numpy.ndarray
        ECEF unit vectors, shape (..., 3).
    """
    lat = np.asarray(lat_rad, float)
    lon = np.asarray(lon_rad, float)
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    east = np.stack([-so, co, np.zeros_like(so)], axis=-1)
    north = np.stack([-sl * co, -sl * so, cl], axis=-1)
    up = np.stack([cl * co, cl * so, sl], axis=-1)
    return east, north, up


def look_vector_ecef(
    lat_rad: ArrayLike, lon_rad: ArrayLike, zenith_rad: ArrayLike, azimuth_rad: ArrayLike
) -> np.ndarray:
    """The unit vector from a ground point toward the satellite.

    Parameters
    ----------
    lat_rad, lon_rad : array_like
        Geodetic latitude and longitude of the ground point, rad.
    zenith_rad : array_like
        The satellite's zenith angle at the ground point, rad.
    azimuth_rad : array_like
        Its azimuth, clockwise from north, rad (the JPSS ``SatelliteZenithAngle`` and
        ``SatelliteAzimuthAngle`` convention).

    Returns
    -------
    numpy.ndarray
        ECEF unit vectors, shape (..., 3).
    """
    east, north, up = enu_basis(lat_rad, lon_rad)
    sz = np.sin(zenith_rad)[..., None]
    return (
        sz * np.sin(azimuth_rad)[..., None] * east
        + sz * np.cos(azimuth_rad)[..., None] * north
        + np.cos(zenith_rad)[..., None] * up
    )


def zenith_azimuth(
    ground_ecef_m: ArrayLike, sat_ecef_m: ArrayLike
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The satellite's zenith angle, azimuth and range seen from ground points on the ellipsoid.

    Parameters
    ----------
    ground_ecef_m, sat_ecef_m : array_like
        Ground points and satellite positions, ECEF, m, shape (..., 3).

    Returns
    -------
    zenith_rad, azimuth_rad, range_m : numpy.ndarray
        Zenith angle and azimuth (clockwise from north), rad, and range, m.
    """
    lat, lon, _ = ecef_to_geodetic(ground_ecef_m)
    east, north, up = enu_basis(lat, lon)
    d = np.asarray(sat_ecef_m) - np.asarray(ground_ecef_m)
    rng = np.linalg.norm(d, axis=-1)
    u = d / rng[..., None]
    zen = np.arccos(np.clip(np.sum(u * up, axis=-1), -1.0, 1.0))
    az = np.arctan2(np.sum(u * east, axis=-1), np.sum(u * north, axis=-1))
    return zen, az, rng


def intersect_ellipsoid(origin_m: ArrayLike, direction: ArrayLike, h_m: ArrayLike = 0.0) -> np.ndarray:
    """The distance along a ray from an ECEF origin to its first crossing of the ellipsoid.

    The ellipsoid is WGS84 grown by *h_m* on both axes (exact for h_m = 0, the IDPS convention). Shapes
    broadcast over the leading axes; the last is 3.

    Parameters
    ----------
    origin_m : array_like
        Ray origins, ECEF, m.
    direction : array_like
        Unit ray directions, ECEF.
    h_m : array_like, optional
        Height the ellipsoid is grown by, m.

    Returns
    -------
    numpy.ndarray
        Distances, m; NaN where the ray misses.
    """
    o = np.asarray(origin_m, float)
    d = np.asarray(direction, float)
    a = A_M + np.asarray(h_m, float)
    b = B_M + np.asarray(h_m, float)
    w = np.stack(np.broadcast_arrays(1.0 / a**2, 1.0 / a**2, 1.0 / b**2), axis=-1)
    qa = np.sum(d * d * w, axis=-1)
    qb = 2.0 * np.sum(o * d * w, axis=-1)
    qc = np.sum(o * o * w, axis=-1) - 1.0
    disc = qb**2 - 4.0 * qa * qc
    with np.errstate(invalid="ignore"):
        t = (-qb - np.sqrt(disc)) / (2.0 * qa)
    return np.where((disc >= 0) & (t > 0), t, np.nan)


def geodetic_up(xyz_m: ArrayLike) -> np.ndarray:
    """The unit normal to the ellipsoid at (or below) ECEF points: geodetic up.

    Parameters
    ----------
    xyz_m : array_like
        ECEF points, m, shape (..., 3).

    Returns
    -------
    numpy.ndarray
        ECEF unit vectors, shape (..., 3).
    """
    lat, lon, _ = ecef_to_geodetic(xyz_m)
    return enu_basis(lat, lon)[2]
