"""WGS84 geodesy of one point, compiled to be inlined in the collocation's kernels: the scalar form of
:func:`monitor.geometry.wgs84.geodetic_to_ecef`."""

from __future__ import annotations

import math

import numba

from monitor.geometry import wgs84


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def ecef_m(lat_rad: float, lon_rad: float, h_m: float) -> tuple[float, float, float]:
    """WGS84 geodetic coordinates to ECEF, inside a compiled kernel.

    With N the prime vertical radius of curvature: x = (N + h) cos(lat) cos(lon), y = (N + h) cos(lat)
    sin(lon), z = (N (1 - e^2) + h) sin(lat).

    Parameters
    ----------
    lat_rad, lon_rad : float
        Geodetic latitude and longitude, rad.
    h_m : float
        Height above the ellipsoid, m.

    Returns
    -------
    x_m, y_m, z_m : float
        The ECEF position, m.
    """
    s = math.sin(lat_rad)
    n = wgs84.A_M / math.sqrt(1.0 - wgs84.E2 * s * s)
    r = (n + h_m) * math.cos(lat_rad)
    return r * math.cos(lon_rad), r * math.sin(lon_rad), (n * (1.0 - wgs84.E2) + h_m) * s
