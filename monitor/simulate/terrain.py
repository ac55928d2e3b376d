"""Where a line of sight meets the terrain, or the first cloud it passes: the point a terrain-corrected
geolocation (GITCO) reports, and the point an instrument sees.

Along the ray p(t) = origin + t los, g(t) = h(p(t)) - H(p(t)) (geodetic height minus the height of the
surface below) is positive above the surface and negative below it. The root lies between the crossing of
a shell above the highest surface and the crossing of the ellipsoid (h = 0). On the few tens of kilometres
of ray involved, the geodetic normal below the ray is the linear interpolation of its ends' normals,
and the geodetic height are quadratics in t (the Earth's curvature; a line through the linear
interpolation of the ends' normals would be ~30 m off sideways in the middle of a 40 km ray from 17 km),
exact at the ends and the middle; the normal is renormalised (the scene's fields are functions of that
unit normal: no trigonometry per step). The final point is converted exactly.

The terrain's slopes stay below 0.4, so a ray meets it once: one bracket from the shell to the ellipsoid.
Clouds with height stand up to 17 km with steep sides, so a ray can cross the surface several times; the
first crossing is bracketed by marching down the ray in steps of at most :data:`MARCH_STEP_M` of ground
distance (the cloud field's cells are 1.1 km). Either way regula falsi (Illinois variant) finds the root
inside its bracket, compiled with the scene's surface (:func:`monitor.simulate.scene._march`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from monitor.geometry import wgs84

TOLERANCE_M = 0.05
ITERATIONS = 12
MARCH_STEP_M = 500.0
SHELL_MARGIN_M = 10.0
NEAR_SURFACE_ITERATIONS = 3  # Bowring iterations for points within ~20 km of the ellipsoid (< 1 mm)


class RayGeometry(NamedTuple):
    """Rays between the shell above the surface and the ellipsoid, each as a fraction x = 0..1 of that
    span: t = t_top + x span (m); the unit normal below is unit(n0 + x (n1 + x n2)); the geodetic height
    is h0 + x (c1 + x c2) (m)."""

    t_top: np.ndarray
    span: np.ndarray
    n0: np.ndarray
    n1: np.ndarray
    n2: np.ndarray
    h0: np.ndarray
    c1: np.ndarray
    c2: np.ndarray


def ray_geometry(o: np.ndarray, d: np.ndarray, t_floor: np.ndarray, top_m: float) -> RayGeometry:
    """The :class:`RayGeometry` of rays from ECEF *o* (R, 3) along unit *d* (R, 3) that meet the ellipsoid
    at *t_floor* (R,), from the shell at *top_m* (m above the ellipsoid) down.

    Parameters
    ----------
    o : numpy.ndarray
        Ray origins, ECEF, m, shape (R, 3).
    d : numpy.ndarray
        Unit directions, shape (R, 3).
    t_floor : numpy.ndarray
        Where they meet the ellipsoid, m, shape (R,).
    top_m : float
        The shell's height above the ellipsoid, m.

    Returns
    -------
    RayGeometry
        The rays from the shell down.
    """
    t_top = wgs84.intersect_ellipsoid(o, d, top_m)
    ts = (t_top, 0.5 * (t_top + t_floor), t_floor)
    geo = [wgs84.ecef_to_geodetic(o + t[:, None] * d, NEAR_SURFACE_ITERATIONS) for t in ts]
    h = [g[2] for g in geo]
    up = [_normal(g[0], g[1]) for g in geo]
    return RayGeometry(
        t_top,
        t_floor - t_top,
        up[0],
        *_quadratic(*up),
        h[0],
        *_quadratic(*h),
    )


def _quadratic(y0: np.ndarray, ym: np.ndarray, y1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(c1, c2) of y0 + x (c1 + x c2) through y0, ym, y1 at x = 0, 1/2, 1."""
    return np.ascontiguousarray(4 * ym - 3 * y0 - y1), np.ascontiguousarray(2 * (y0 + y1) - 4 * ym)


def _normal(lat_rad: np.ndarray, lon_rad: np.ndarray) -> np.ndarray:
    """Unit geodetic normals (R, 3), ECEF, at *lat_rad*, *lon_rad*."""
    c = np.cos(lat_rad)
    return np.stack([c * np.cos(lon_rad), c * np.sin(lon_rad), np.sin(lat_rad)], -1)


# (rays, steps, each ray's index among the ones given, out t) -> None
March = Callable[[RayGeometry, np.ndarray, np.ndarray, np.ndarray], None]


def first_crossing(
    origin_m: np.ndarray,
    los: np.ndarray,
    top_m: float,
    step_m: float,
    march: March,
    floor_height: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Distance (m) along unit *los* (..., 3) from ECEF *origin_m* to the first crossing of a surface at
    most *top_m* high, and the point's geodetic (lat_rad, lon_rad, h_m); NaN where the ray misses the
    Earth. *march(rays, steps, index, out)* finds each ray's crossing (*index*: the rays' places among
    those given, flattened) in *steps* equal steps from the shell down
    (steps of at most *step_m* of ground distance; inf: one bracket). Given *floor_height(lat_rad,
    lon_rad)*, the surface is met once: a ray whose ellipsoid point has no surface above it ends there.

    Parameters
    ----------
    origin_m : numpy.ndarray
        Ray origins, ECEF, m.
    los : numpy.ndarray
        Unit directions, shape (..., 3).
    top_m : float
        The surface's highest point, m.
    step_m : float
        The march's step of ground distance, m (inf: one bracket).
    march : March
        Finds each ray's crossing.
    floor_height : callable, optional
        The surface below which a ray has crossed, m, of (lat_rad, lon_rad).

    Returns
    -------
    distance_m, lat_rad, lon_rad, h_m : numpy.ndarray
        NaN where the ray misses the Earth.
    """
    o = np.ascontiguousarray(np.broadcast_to(np.asarray(origin_m, float), np.shape(los)).reshape(-1, 3))
    d = np.ascontiguousarray(np.asarray(los, float).reshape(-1, 3))
    shape = np.shape(los)[:-1]
    t = wgs84.intersect_ellipsoid(o, d)
    lat, lon, h = np.full((3, len(t)), np.nan)
    act = np.flatnonzero(np.isfinite(t))
    if floor_height is not None:
        lat[act], lon[act] = wgs84.surface_to_geodetic(o[act] + t[act, None] * d[act])
        h[act] = 0.0
        act = act[np.nan_to_num(floor_height(lat[act], lon[act])) > 0]
    if act.size:
        ray = ray_geometry(o[act], d[act], t[act], top_m + SHELL_MARGIN_M)
        ground_m = np.sqrt(np.maximum(ray.span**2 - (top_m + SHELL_MARGIN_M) ** 2, 0.0))
        steps = np.maximum(np.ceil(ground_m / step_m), 1.0)
        hit = np.empty(act.size)
        march(ray, steps, act, hit)
        t[act] = hit
        lat[act], lon[act], h[act] = wgs84.ecef_to_geodetic(
            o[act] + hit[:, None] * d[act], NEAR_SURFACE_ITERATIONS
        )
    return t.reshape(shape), lat.reshape(shape), lon.reshape(shape), h.reshape(shape)
