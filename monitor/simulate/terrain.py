"""Where a line of sight meets the terrain: the point a terrain-corrected geolocation (GITCO) reports.

Along the ray p(t) = origin + t los, g(t) = h(p(t)) - H(lat(t), lon(t)) (geodetic height minus the
terrain height below) is positive above the terrain and negative below it. The root lies between the
crossing of a shell above the highest terrain and the crossing of the ellipsoid (h = 0); where the terrain
is at sea level there, the ellipsoid point is the answer. Elsewhere the root is found by regula falsi
(Illinois variant). On the few kilometres of ray involved, latitude and longitude are linear in t to
a few centimetres, and the geodetic height is a quadratic in t (the Earth's curvature), so each step
costs one terrain look-up; the final point is converted exactly.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from monitor.geometry import wgs84

HeightFn = Callable[[np.ndarray, np.ndarray], np.ndarray]  # terrain height (m) at (lat_rad, lon_rad)
TOLERANCE_M = 0.05
NEAR_SURFACE_ITERATIONS = 2  # Bowring iterations for points within a few km of the ellipsoid (< 1 mm)


def intersect_terrain(
    origin_m: np.ndarray, los: np.ndarray, height_fn: HeightFn, top_m: float, iterations: int = 12
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Distance (m) along unit *los* (..., 3) from ECEF *origin_m* to the terrain, and the point's
    geodetic (lat_rad, lon_rad, h_m). *height_fn(lat_rad, lon_rad)* gives the terrain height (m), at
    most *top_m*. NaN where the ray misses the Earth."""
    o = np.broadcast_to(np.asarray(origin_m, float), np.shape(los)).reshape(-1, 3)
    d = np.asarray(los, float).reshape(-1, 3)
    shape = np.shape(los)[:-1]
    t = wgs84.intersect_ellipsoid(o, d)
    lat, lon = wgs84.surface_to_geodetic(o + t[:, None] * d)
    h = np.zeros(lat.shape)
    ground = np.nan_to_num(height_fn(lat, lon)).astype(float)
    act = np.flatnonzero(np.isfinite(t) & (ground > 0))
    if act.size:
        t[act] = _root(o[act], d[act], t[act], -ground[act], height_fn, top_m + 10.0, iterations)
        lat[act], lon[act], h[act] = wgs84.ecef_to_geodetic(
            o[act] + t[act, None] * d[act], NEAR_SURFACE_ITERATIONS
        )
    return t.reshape(shape), lat.reshape(shape), lon.reshape(shape), h.reshape(shape)


def _root(
    o: np.ndarray,
    d: np.ndarray,
    t_floor: np.ndarray,
    g_floor: np.ndarray,
    height_fn: HeightFn,
    top_m: float,
    iterations: int,
) -> np.ndarray:
    t_top = wgs84.intersect_ellipsoid(o, d, top_m)
    ts = (t_top, 0.5 * (t_top + t_floor), t_floor)
    geo = [wgs84.ecef_to_geodetic(o + t[:, None] * d, NEAR_SURFACE_ITERATIONS) for t in ts]
    span = t_floor - t_top
    lat0, lat1 = geo[0][0], geo[2][0]
    lon0 = geo[0][1]
    dlon = np.angle(np.exp(1j * (geo[2][1] - lon0)))  # unwrapped across the 180 deg meridian
    h0, hm, h1 = (g[2] for g in geo)
    # geodetic height along the ray: the quadratic through the three exact heights, in x = (t - t_top)/span
    c1 = 4 * hm - 3 * h0 - h1
    c2 = 2 * (h0 + h1) - 4 * hm

    def g(tt: np.ndarray) -> np.ndarray:
        x = (tt - t_top) / span
        return h0 + x * (c1 + x * c2) - height_fn(lat0 + x * (lat1 - lat0), lon0 + x * dlon)

    a, ga = t_top, g(t_top)  # above the terrain: g > 0
    b, gb = t_floor.copy(), g_floor  # below: g < 0
    last = np.zeros(len(a), np.int8)  # which end moved last: +1 a, -1 b
    c = b
    for _ in range(iterations):
        c = b - gb * (b - a) / (gb - ga)
        gc = g(c)
        up = gc > 0
        gb = np.where(up & (last == 1), 0.5 * gb, gb)  # Illinois: the same end moved twice, halve the other
        ga = np.where(~up & (last == -1), 0.5 * ga, ga)
        a, ga = np.where(up, c, a), np.where(up, gc, ga)
        b, gb = np.where(up, b, c), np.where(up, gb, gc)
        last = np.where(up, 1, -1).astype(np.int8)
        if np.all(np.abs(gc) < TOLERANCE_M):
            break
    return c
