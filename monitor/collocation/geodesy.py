"""WGS84 geodesy of one point, compiled to be inlined in the collocation's kernels: the scalar forms of
:func:`monitor.geometry.wgs84.geodetic_to_ecef` and :func:`monitor.geometry.wgs84.ecef_to_geodetic`."""

from __future__ import annotations

import math

import numba

from monitor.geometry import wgs84


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def ecef_m(lat_rad: float, lon_rad: float, h_m: float) -> tuple[float, float, float]:
    """WGS84 geodetic (rad, rad, m above the ellipsoid) to ECEF (m), N the prime vertical radius of
    curvature: x = (N + h) cos(lat) cos(lon), y = (N + h) cos(lat) sin(lon),
    z = (N (1 - e^2) + h) sin(lat)."""
    s = math.sin(lat_rad)
    n = wgs84.A_M / math.sqrt(1.0 - wgs84.E2 * s * s)
    r = (n + h_m) * math.cos(lat_rad)
    return r * math.cos(lon_rad), r * math.sin(lon_rad), (n * (1.0 - wgs84.E2) + h_m) * s


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def geodetic_rad_m(x_m: float, y_m: float, z_m: float) -> tuple[float, float, float]:
    """ECEF (m) to WGS84 geodetic (rad, rad, m) by three of Bowring's iterations, enough within ~10 km of
    the ellipsoid."""
    p = math.hypot(x_m, y_m)
    lat = math.atan2(z_m, p * (1.0 - wgs84.E2))
    for _ in range(3):
        s = math.sin(lat)
        n = wgs84.A_M / math.sqrt(1.0 - wgs84.E2 * s * s)
        h = p * math.cos(lat) + z_m * s - wgs84.A_M**2 / n
        lat = math.atan2(z_m, p * (1.0 - wgs84.E2 * n / (n + h)))
    s = math.sin(lat)
    n = wgs84.A_M / math.sqrt(1.0 - wgs84.E2 * s * s)
    return lat, math.atan2(y_m, x_m), p * math.cos(lat) + z_m * s - wgs84.A_M**2 / n
