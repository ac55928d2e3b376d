"""A synthetic Earth in the thermal infrared: ocean, land, terrain and broken cloud, deterministic by seed.

The scene is an emitting temperature T(lat, lon, h) (K): sea-surface temperature falling with latitude,
land warmer by day and colder by night with its own texture, colder with altitude (lapse rate), and
clouds (more of them over high ground) whose tops are colder, mixed by a cloud fraction with soft edges.

Fields live on the sphere, not on a latitude/longitude grid, so that nothing breaks at the 180 deg
meridian or near the poles: each is a blend of three periodic random fields on the planes normal to
the x, y and z axes ("triplanar"), weighted by the fourth power of the direction cosines and scaled to
keep unit variance. The cloud field has 1.1 km cells (period ~2250 km), the land, terrain, cloud-top and
texture fields 4.4 km cells, so an orbit segment sees clouds at scales from ~2 km to hundreds of km.

Terrain (optional): ranges and plateaus of 1-4 km over land, rising from sea level over a coastal ramp
of some tens of km. Its slopes stay below ``MAX_SLOPE`` (0.4, ~22 deg), so a line of sight from the
satellite meets it once except on the steepest slopes seen at the very edge of the VIIRS swath (at view
zenith z a ray can meet a slope s twice only when s > cot z; cot 68 deg = 0.4).

Clouds with height (optional, :mod:`monitor.simulate.clouds`): a cloud top stands at the height its
temperature implies under a law (a lapse rate or a profile) from the surface air temperature below it (the
sea-surface temperature of its latitude). Where the cover is partial (the soft edges) the cloud surface
stands at cover x that height, so the scene is one surface ``top_m(lat, lon)``, the terrain or the cloud
above it, with steep sides at the cloud edges; the emitting temperature of a point on it is the flat
scene's at the same (lat, lon). Clouds on the ground are the law ``ground``: the surface is the terrain.

Wind (optional, :class:`Wind`): the clouds, not the land, move along a great circle; a point at time t
reads the cloud fields where its clouds stood at the reference time, so each ray sees them where they are
at its own time.

Spectra add a simple atmosphere: R(nu) = tau(nu) B(nu, T) + (1 - tau(nu)) B(nu, T_atm).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
from numpy.typing import ArrayLike

from monitor.compiled.threads import KERNEL_LOCK
from monitor.instrument.spectral import planck_radiance
from monitor.simulate import terrain
from monitor.simulate.clouds import CEILING_M, FLAT, CloudHeights

EARTH_RADIUS_KM = 6371.0
FINE_KM, FINE_N = 1.1, 2048
COARSE_KM, COARSE_N = 4.4, 512
T_ATM_K = 262.0
SW_FROM_CM1 = 2000.0  # the short-wave atmosphere of transmittance() from here on
LAPSE_K_PER_M = 6.5e-3
LAND_DAY_K, LAND_NIGHT_K = 6.0, -5.0
MAX_SLOPE = 0.4
MAX_HEIGHT_M = 4000.0
CLOUD_PER_M = 0.15e-3  # more cloud over high ground: the cloud field's threshold drops 0.15 per km
# the cloud field's values over which the cover rises from 0 to 1 (the field has unit variance): "soft"
# edges blend cloud and surface over a few km, "sharp" ones within a fine cell (the blobs of a 1 km grid)
EDGES = {"soft": 0.6, "sharp": 0.02}


def _random_field(rng: np.random.Generator, n: int, slope: float, low_cut: float) -> np.ndarray:
    """Zero-mean unit-variance periodic field with power spectrum ~ k^-slope above *low_cut* cycles."""
    kx = np.fft.fftfreq(n) * n
    ky = np.fft.rfftfreq(n) * n
    k = np.hypot(kx[:, None], ky[None, :])
    amp = np.where(k >= low_cut, np.maximum(k, 1.0) ** (-slope / 2.0), 0.0)
    spec = amp * (rng.standard_normal(k.shape) + 1j * rng.standard_normal(k.shape))
    f = np.fft.irfft2(spec, s=(n, n))
    return ((f - f.mean()) / f.std()).astype(np.float32)


def _unit_vectors(lat_rad: ArrayLike, lon_rad: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    lat = np.asarray(lat_rad, np.float64)
    lon = np.asarray(lon_rad, np.float64)
    c = np.cos(lat)
    return c * np.cos(lon), c * np.sin(lon), np.sin(lat)


@numba.njit(cache=True, nogil=True, inline="always")
def _sample(x: float, y: float, z: float, flat: np.ndarray, n: int, scale: float, out: np.ndarray) -> None:
    """out (C,) = the triplanar blend at unit vector (x, y, z) of the fields *flat* (3, n * n, C): for
    each plane the bilinear sample at the point's two in-plane coordinates (times *scale*), weighted by the
    fourth power of the direction cosine normal to the plane over their root sum of squares."""
    mask = n - 1  # n is a power of two: modulo by mask
    nc = flat.shape[2]
    c = (x, y, z)
    w = (x**4, y**4, z**4)
    norm = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    for ch in range(nc):
        out[ch] = 0.0
    for p in range(3):
        u = c[(p + 1) % 3] * scale
        v = c[(p + 2) % 3] * scale
        u0 = np.floor(u)
        v0 = np.floor(v)
        fu = u - u0
        fv = v - v0
        i0 = np.int32(u0) & mask
        j0 = np.int32(v0) & mask
        i1 = ((i0 + 1) & mask) * n
        j1 = (j0 + 1) & mask
        i0 *= n
        wp = w[p] / norm
        for ch in range(nc):
            a = flat[p, i0 + j0, ch]
            a += (flat[p, i0 + j1, ch] - a) * fv
            b = flat[p, i1 + j0, ch]
            b += (flat[p, i1 + j1, ch] - b) * fv
            a += (b - a) * fu
            out[ch] += a * wp


@numba.njit(cache=True, nogil=True)
def _triplanar_samples(
    x: np.ndarray, y: np.ndarray, z: np.ndarray, flat: np.ndarray, n: int, scale: float, out: np.ndarray
) -> None:
    """out (P, C) = :func:`_sample` at unit vectors (x, y, z) (P,): one pass per point, the arithmetic of
    the array form without its (P, C) temporaries."""
    for k in range(x.shape[0]):
        _sample(x[k], y[k], z[k], flat, n, scale, out[k])


# The scene's rules, each written once as a ufunc: the array methods of Scene and the compiled march
# (_surface_m) call the same ones.
@numba.vectorize(["float64(float64, float64, float64, float64, float64)"], cache=True)
def _terrain_m(land: float, relief: float, ridges: float, land_threshold: float, gain: float) -> float:
    """Terrain height (m): a coastal ramp times ranges (ridged noise) on plateaus (a squashed field)."""
    coast = min(max(land - land_threshold, 0.0), 1.0)
    coast = coast * coast * (3 - 2 * coast)  # smoothstep: no cliff at the shore
    plateau = 2200.0 + 1300.0 * np.tanh(1.2 * relief)
    ridge = 700.0 * (1.0 - abs(np.tanh(ridges)))
    return coast * min(plateau + ridge, MAX_HEIGHT_M) * gain


@numba.vectorize(["float64(float64, float64, float64, float64)"], cache=True)
def _cover(cloud: float, threshold: float, ground_m: float, edge: float) -> float:
    """Cloud cover 0..1 of the cloud field's value (more cloud over high ground), rising from 0 to 1 over
    *edge* of the field's values (:data:`EDGES`)."""
    return min(max((cloud - threshold + CLOUD_PER_M * ground_m) / edge, 0.0), 1.0)


@numba.vectorize(["float64(float64)"], cache=True)
def _top_k(top: float) -> float:
    """Cloud-top temperature (K) of the cloud-top field's value."""
    return 245.0 + 18.0 * top


@numba.vectorize(["float64(float64)"], cache=True)
def _air_k(sin_lat: float) -> float:
    """Sea-surface (and surface air) temperature (K) by the sine of the latitude."""
    return 301.0 - 12.0 * sin_lat * sin_lat


@numba.njit(cache=True, nogil=True, inline="always")
def _turned(x, y, z, axis, c, s):  # type: ignore[no-untyped-def]
    """Unit vector (x, y, z) turned about unit *axis* (3,) by the angle of cosine *c* and sine *s*
    (Rodrigues)."""
    kx, ky, kz = axis[0], axis[1], axis[2]
    dot = (kx * x + ky * y + kz * z) * (1.0 - c)
    return (
        x * c + (ky * z - kz * y) * s + kx * dot,
        y * c + (kz * x - kx * z) * s + ky * dot,
        z * c + (kx * y - ky * x) * s + kz * dot,
    )


@numba.njit(cache=True, nogil=True)
def _surface_m(x, y, z, c, s, fields, params, axis, law_k, law_m, clouds, buf):  # type: ignore[no-untyped-def]
    """Height (m) of the surface a ray meets at unit normal (x, y, z): the terrain, and with *clouds* the
    cloud standing on it (cover x its top's height above the terrain: tops and sides), the clouds' fields
    read where the wind had them at the scene's reference time: (x, y, z) turned about *axis* (3,) by
    the angle of cosine *c* and sine *s* (:class:`Wind`). *fields* the cloud, surface and shape fields'
    (flat, n, scale); *params* (cloud threshold, land threshold, relief gain, terrain 0/1, cover edge);
    the law's knots (cooling K, height m); *buf* (3,) scratch."""
    cloud, surf, shape = fields
    cloud_threshold, land_threshold, gain, terrain, edge = params
    ground = 0.0
    if terrain:
        _sample(x, y, z, shape[0], shape[1], shape[2], buf)
        ground = _terrain_m(buf[0], buf[1], buf[2], land_threshold, gain)
    if not clouds:
        return ground
    x, y, z = _turned(x, y, z, axis, c, s)
    _sample(x, y, z, cloud[0], cloud[1], cloud[2], buf)
    cover = _cover(buf[0], cloud_threshold, ground, edge)
    if cover <= 0.0:
        return ground
    _sample(x, y, z, surf[0], surf[1], surf[2], buf)
    height = _piecewise(_air_k(z) - _top_k(buf[0]), law_k, law_m)
    return ground + cover * max(height - ground, 0.0)


@numba.njit(cache=True, nogil=True, inline="always")
def _piecewise(x: float, knots_x: np.ndarray, knots_y: np.ndarray) -> float:
    """np.interp of one value (held at the ends), without its array allocation."""
    if x <= knots_x[0]:
        return knots_y[0]
    for i in range(1, knots_x.shape[0]):
        if x < knots_x[i]:
            f = (x - knots_x[i - 1]) / (knots_x[i] - knots_x[i - 1])
            return knots_y[i - 1] + f * (knots_y[i] - knots_y[i - 1])
    return knots_y[-1]


@numba.njit(cache=True, nogil=True)
def _surface_points(x, y, z, turn, fields, params, axis, law_k, law_m, clouds, out):  # type: ignore[no-untyped-def]
    """out (P,) = :func:`_surface_m` at unit normals (x, y, z) (P,), the wind's turn (cos, sin) (P,)."""
    buf = np.empty(3, np.float32)
    c, s = turn
    for k in range(x.shape[0]):
        out[k] = _surface_m(x[k], y[k], z[k], c[k], s[k], fields, params, axis, law_k, law_m, clouds, buf)


@numba.njit(cache=True, nogil=True, inline="always")
def _above_m(r, x, n0, n1, n2, h0, c1, c2, turn, fields, params, axis, law_k, law_m, clouds, buf):  # type: ignore[no-untyped-def]
    """Height (m) of ray *r* above the surface (:func:`_surface_m`) at fraction *x* of its span
    (:class:`monitor.simulate.terrain.RayGeometry`: the normal below it and its height are quadratics)."""
    nx = n0[r, 0] + x * (n1[r, 0] + x * n2[r, 0])
    ny = n0[r, 1] + x * (n1[r, 1] + x * n2[r, 1])
    nz = n0[r, 2] + x * (n1[r, 2] + x * n2[r, 2])
    norm = np.sqrt(nx * nx + ny * ny + nz * nz)
    height = h0[r] + x * (c1[r] + x * c2[r])
    c, s = turn[0][r], turn[1][r]
    return height - _surface_m(
        nx / norm, ny / norm, nz / norm, c, s, fields, params, axis, law_k, law_m, clouds, buf
    )


@numba.njit(cache=True, nogil=True, parallel=True)
def _march(ray, turn, steps, fields, params, axis, law_k, law_m, clouds, iterations, tolerance_m, out):  # type: ignore[no-untyped-def]
    """out (R,) = the distance along each ray of :class:`monitor.simulate.terrain.RayGeometry` *ray* to
    its first crossing of the surface (:func:`_surface_m`, the wind's turn (cos, sin) (R,) of each ray's
    time): march *steps* (R,) equal steps from the top shell to the ellipsoid; the first that ends on or
    below the surface brackets the crossing, which regula falsi (Illinois) finds to *tolerance_m*."""
    t_top, span, n0, n1, n2, h0, c1, c2 = ray
    # a parallel loop takes arrays, not tuples of them: taken apart here, put together in the loop
    (cloud, cloud_n, cloud_s), (surf, surf_n, surf_s), (shape, shape_n, shape_s) = fields
    cos_turn, sin_turn = turn
    for r in numba.prange(t_top.shape[0]):
        fields = ((cloud, cloud_n, cloud_s), (surf, surf_n, surf_s), (shape, shape_n, shape_s))
        turn = (cos_turn, sin_turn)
        buf = np.empty(3, np.float32)
        a, ga = 0.0, 0.0
        b, gb = 1.0, 0.0
        for k in range(int(steps[r]) + 1):
            x = min(k / steps[r], 1.0)
            g = _above_m(r, x, n0, n1, n2, h0, c1, c2, turn, fields, params, axis, law_k, law_m, clouds, buf)
            if g > 0.0 and k < steps[r]:
                a, ga = x, g
            else:
                b, gb = x, min(g, 0.0)  # the ellipsoid (h = 0 to rounding) ends every ray
                break
        c, last = b, 0
        for _ in range(iterations):
            c = b if gb == 0.0 else b - gb * (b - a) / (gb - ga)
            gc = _above_m(r, c, n0, n1, n2, h0, c1, c2, turn, fields, params, axis, law_k, law_m, clouds, buf)
            if abs(gc) < tolerance_m:
                break
            if gc > 0:
                if last == 1:
                    gb *= 0.5  # Illinois: the same end moved twice, halve the other
                a, ga, last = c, gc, 1
            else:
                if last == -1:
                    ga *= 0.5
                b, gb, last = c, gc, -1
        out[r] = t_top[r] + c * span[r]


class _Triplanar:
    """Bilinear samples of stacked periodic fields (3 planes, n, n, channels) blended over the three
    planes (:func:`_triplanar_samples`)."""

    def __init__(self, fields: np.ndarray, cell_km: float) -> None:
        self.n = fields.shape[1]
        self.flat = np.ascontiguousarray(fields.reshape(3, self.n * self.n, -1), np.float32)
        self.scale = np.float32(EARTH_RADIUS_KM / cell_km)

    def __call__(self, xyz: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
        x, y, z = (np.ascontiguousarray(c, np.float32) for c in xyz)
        shape = x.shape
        out = np.empty((x.size, self.flat.shape[2]), np.float32)
        _triplanar_samples(x.ravel(), y.ravel(), z.ravel(), self.flat, self.n, self.scale, out)
        return out.reshape(shape + (self.flat.shape[2],))


@dataclass(frozen=True)
class Wind:
    """Clouds carried at *speed_m_s* along a great circle: at unix time t they stand where they stood at
    *reference_s*, turned about the unit ECEF *axis* by speed (t - reference) / Earth radius (positive:
    the sense of the right hand about *axis*; about the orbit's normal, the direction of flight)."""

    axis: tuple[float, float, float]
    speed_m_s: float
    reference_s: float

    def turn_back(self, unix_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(cos, sin) of the angle that turns a point at *unix_s* back to where its clouds were at the
        reference time.

        Parameters
        ----------
        unix_s : array_like
            UTC seconds since 1970.

        Returns
        -------
        cos, sin : numpy.ndarray
            The angle's.
        """
        angle = -self.speed_m_s / (EARTH_RADIUS_KM * 1e3) * (np.asarray(unix_s, float) - self.reference_s)
        return np.cos(angle), np.sin(angle)


STILL = Wind((0.0, 0.0, 1.0), 0.0, 0.0)


class Scene:
    """Emitting temperature and terrain of the synthetic Earth.

    ``temperature_k(lat_rad, lon_rad, height_m, unix_s)`` and ``height_m(lat_rad, lon_rad)`` (zero
    without *terrain*); *night* makes land colder than the sea instead of warmer. *clouds* stands the
    cloud tops at the height their temperature implies (``top_m``, the surface a line of sight meets
    first). *edges* (:data:`EDGES`) how sharply the clouds' cover ends; *wind* carries the clouds (not the
    land) over the ground.

    Parameters
    ----------
    seed : int, optional
        The scene's seed.
    cloud_fraction : float, optional
        The cloud cover.
    land_fraction : float, optional
        The land's share.
    terrain : bool, optional
        1-4 km ranges and plateaus on land.
    night : bool, optional
        Land colder than the sea.
    clouds : CloudHeights, optional
        The cloud-top law.
    edges : str, optional
        ``soft`` or ``sharp`` (:data:`EDGES`).
    wind : Wind, optional
        What carries the clouds.
    """

    def __init__(
        self,
        seed: int = 0,
        cloud_fraction: float = 0.45,
        land_fraction: float = 0.3,
        terrain: bool = False,
        night: bool = False,
        clouds: CloudHeights = FLAT,
        edges: str = "soft",
        wind: Wind = STILL,
    ):
        rng = np.random.default_rng(seed)
        self.edge = EDGES[edges]
        self.wind = wind
        self._axis = np.asarray(wind.axis, np.float64)
        self.terrain = terrain
        self.clouds = clouds
        self.land_offset_k = LAND_NIGHT_K if night else LAND_DAY_K
        self.cloud = _Triplanar(
            np.stack([_random_field(rng, FINE_N, 3.2, 4) for _ in range(3)])[..., None], FINE_KM
        )
        # land, terrain relief and ridges (the shape of the Earth); cloud top and land texture
        coarse = [[_random_field(rng, COARSE_N, s, 2) for s in (3.6, 4.0, 3.0, 3.0, 2.5)] for _ in range(3)]
        self.shape = _Triplanar(np.stack([np.stack(c[:3], -1) for c in coarse]), COARSE_KM)
        self.surface = _Triplanar(np.stack([np.stack(c[3:], -1) for c in coarse]), COARSE_KM)
        probe = self.shape(
            _unit_vectors(*np.radians(np.meshgrid(np.linspace(-80, 80, 161), np.linspace(-180, 180, 361))))
        )
        self.cloud_threshold = float(np.quantile(self.cloud.flat[0, ::61, 0], 1.0 - cloud_fraction))
        self.land_threshold = float(np.quantile(probe[..., 0], 1.0 - land_fraction))
        self.relief_gain = 1.0
        if terrain:
            self.relief_gain = min(1.0, MAX_SLOPE / self._max_slope())

    def _height(self, land: np.ndarray, relief: np.ndarray, ridges: np.ndarray) -> np.ndarray:
        """Terrain height (m) of the shape fields' values (:func:`_terrain_m`)."""
        return _terrain_m(land, relief, ridges, self.land_threshold, self.relief_gain).astype(np.float32)

    def _max_slope(self) -> float:
        """Largest terrain slope on a 1 km probe grid over a few thousand km (the field is stationary)."""
        step_rad = 1.0 / EARTH_RADIUS_KM
        lat = np.arange(-0.15, 0.15, step_rad)
        lat, lon = np.meshgrid(lat, np.arange(0.0, 0.3, step_rad), indexing="ij")
        h = self._height(*np.moveaxis(self.shape(_unit_vectors(lat, lon)), -1, 0))
        gy, gx = np.gradient(h, 1000.0)
        return float(np.max(np.hypot(gx, gy)))

    def height_m(self, lat_rad: ArrayLike, lon_rad: ArrayLike) -> np.ndarray:
        """Terrain height (m) above the ellipsoid at geodetic *lat_rad*, *lon_rad*; float32.

        Parameters
        ----------
        lat_rad, lon_rad : array_like
            Geodetic latitude and longitude, rad.

        Returns
        -------
        numpy.ndarray
            m, float32.
        """
        if not self.terrain:
            return np.zeros(np.shape(lat_rad), np.float32)
        return self._height(*np.moveaxis(self.shape(_unit_vectors(lat_rad, lon_rad)), -1, 0))

    @property
    def ceiling_m(self) -> float:
        """The highest the scene's surface (terrain or cloud) stands (m).

        Returns
        -------
        float
            m.
        """
        return MAX_HEIGHT_M if self.clouds.flat else max(MAX_HEIGHT_M, CEILING_M)

    def _compiled(self, clouds: bool) -> tuple:
        """The arguments of :func:`_surface_m` after the point and the wind's turn: fields, parameters,
        the wind's axis, law, *clouds*."""
        fields = tuple((f.flat, f.n, f.scale) for f in (self.cloud, self.surface, self.shape))
        params = (self.cloud_threshold, self.land_threshold, self.relief_gain, float(self.terrain), self.edge)
        law_k, law_m = self.clouds.knots()
        return fields, params, self._axis, law_k, law_m, clouds and not self.clouds.flat

    def _turn_back(self, unix_s: ArrayLike, shape: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        """The wind's (cos, sin) turn back to the reference time (:meth:`Wind.turn_back`) at *unix_s*
        broadcast to *shape*, flattened."""
        return tuple(  # type: ignore[return-value]
            np.ascontiguousarray(np.broadcast_to(a, shape), np.float64).ravel()
            for a in self.wind.turn_back(unix_s)
        )

    def top_m(self, lat_rad: ArrayLike, lon_rad: ArrayLike, unix_s: ArrayLike = 0.0) -> np.ndarray:
        """Height (m) of the surface a line of sight meets at geodetic *lat_rad*, *lon_rad* at *unix_s*: the
        terrain, or a cloud's top or side standing on it (cover x the top's height above the terrain).

        Parameters
        ----------
        lat_rad, lon_rad : array_like
            Geodetic latitude and longitude, rad.
        unix_s : array_like
            UTC seconds since 1970.

        Returns
        -------
        numpy.ndarray
            m.
        """
        x, y, z = (np.ascontiguousarray(c, np.float64).ravel() for c in _unit_vectors(lat_rad, lon_rad))
        out = np.empty(x.size)
        _surface_points(x, y, z, self._turn_back(unix_s, np.shape(lat_rad)), *self._compiled(True), out)
        return out.reshape(np.shape(lat_rad)).astype(np.float32)

    def intersect(
        self, origin_m: np.ndarray, los: np.ndarray, clouds: bool = True, unix_s: ArrayLike = 0.0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Distance (m) along unit *los* (..., 3) from ECEF *origin_m* to the first surface it meets (the
        terrain, and with *clouds* the clouds standing on it where the wind has them at *unix_s*,
        broadcast to the rays), and that point's geodetic (lat_rad, lon_rad, h_m); NaN where the ray
        misses the Earth. Terrain alone is met once: one bracket; clouds are bracketed by marching
        (:mod:`monitor.simulate.terrain`).

        Parameters
        ----------
        origin_m : numpy.ndarray
            Ray origins, ECEF, m.
        los : numpy.ndarray
            Unit directions, ECEF, shape (..., 3).
        clouds : bool, optional
            Meet the clouds too.
        unix_s : array_like, optional
            When, UTC s (where the wind has the clouds).

        Returns
        -------
        distance_m, lat_rad, lon_rad, h_m : numpy.ndarray
            NaN where the ray misses.
        """
        tall = clouds and not self.clouds.flat
        cos_turn, sin_turn = self._turn_back(unix_s, np.shape(los)[:-1])
        return terrain.first_crossing(
            origin_m,
            los,
            self.ceiling_m if tall else MAX_HEIGHT_M,
            terrain.MARCH_STEP_M if tall else np.inf,
            lambda ray, steps, index, out: _locked(
                _march,
                ray,
                (cos_turn[index], sin_turn[index]),
                steps,
                *self._compiled(clouds),
                terrain.ITERATIONS,
                terrain.TOLERANCE_M,
                out,
            ),
            None if tall else self.height_m,
        )

    def temperature_k(
        self,
        lat_rad: ArrayLike,
        lon_rad: ArrayLike,
        height_m: ArrayLike | None = None,
        unix_s: ArrayLike = 0.0,
        cloudy: bool = True,
    ) -> np.ndarray:
        """Emitting temperature (K) at geodetic *lat_rad*, *lon_rad* and terrain height *height_m*, the
        clouds where the wind has them at *unix_s*; not *cloudy*: the ground's, as if no cloud were
        there.

        Parameters
        ----------
        lat_rad, lon_rad : array_like
            Geodetic latitude and longitude, rad.
        height_m : array_like, optional
            Terrain height, m.
        unix_s : array_like, optional
            When, UTC s.
        cloudy : bool, optional
            False: the ground's, as if no cloud were there.

        Returns
        -------
        numpy.ndarray
            K.
        """
        xyz = _unit_vectors(lat_rad, lon_rad)
        land = self.shape(xyz)[..., 0]
        h = np.zeros(np.shape(lat_rad), np.float32) if height_m is None else np.asarray(height_m, np.float32)
        texture = self.surface(xyz)[..., 1]
        land_frac = np.clip((land - self.land_threshold) / 0.05, 0.0, 1.0)
        surface = _air_k(xyz[2]) + land_frac * (self.land_offset_k + 3.0 * texture) - LAPSE_K_PER_M * h
        if not cloudy:
            return surface.astype(np.float32)
        moved = xyz
        if self.wind.speed_m_s:
            shape = np.shape(lat_rad)
            c, s = (a.reshape(shape) for a in self._turn_back(unix_s, shape))
            moved = _turned(*xyz, self._axis, c, s)
        top = self.surface(moved)[..., 0]
        cover = _cover(self.cloud(moved)[..., 0], self.cloud_threshold, h, self.edge)
        return (surface * (1 - cover) + np.minimum(_top_k(top), surface) * cover).astype(np.float32)


def _locked(kernel: Callable[..., None], *args: Any) -> None:
    """Run a parallel *kernel* holding :data:`KERNEL_LOCK` (one parallel region at a time)."""
    with KERNEL_LOCK:
        kernel(*args)


def transmittance(wavenumber_cm1: ArrayLike) -> np.ndarray:
    """A simple clear-sky transmittance: in the long wave a moist window with CO2 below 760 cm-1 and ozone
    near 1040 cm-1 (more water at 12 um than at 11: M16 sees a warm clear scene colder than M15); in the
    short wave (from :data:`SW_FROM_CM1`) the 4 um window, bounded by CO2 below 2395 cm-1.

    Parameters
    ----------
    wavenumber_cm1 : array_like
        cm-1.

    Returns
    -------
    numpy.ndarray
        0..1.
    """
    nu = np.asarray(wavenumber_cm1, float)
    with np.errstate(over="ignore"):  # each formula is evaluated on both bands; np.where keeps its own
        k = 0.12 + 0.25 * ((nu - 900.0) / 150.0) ** 2
        k += 4.0 / (1.0 + np.exp((nu - 740.0) / 8.0))
        k += 1.2 * np.exp(-0.5 * ((nu - 1042.0) / 18.0) ** 2)
        k += 0.08 * (1.0 + np.sin(nu * 2.1)) * np.exp(-0.5 * ((nu - 870.0) / 120.0) ** 2)
        # the short-wave window (VIIRS M13): a weak continuum, the CO2 band below 2395 cm-1, water above
        k_sw = 0.01 + 0.1 * ((nu - 2500.0) / 100.0) ** 2 + 3.0 / (1.0 + np.exp((nu - 2395.0) / 6.0))
    return np.exp(-np.where(nu < SW_FROM_CM1, k, k_sw))


def spectra(wavenumber_cm1: ArrayLike, mean_planck: ArrayLike) -> np.ndarray:
    """Top-of-atmosphere spectra from the cone-mean surface Planck radiance (..., nchan).

    Parameters
    ----------
    wavenumber_cm1 : array_like
        cm-1.
    mean_planck : array_like
        Cone-mean surface Planck radiance, mW/(m2 sr cm-1).

    Returns
    -------
    numpy.ndarray
        mW/(m2 sr cm-1), shape (..., nchan).
    """
    tau = transmittance(wavenumber_cm1)
    return tau * mean_planck + (1.0 - tau) * planck_radiance(wavenumber_cm1, T_ATM_K)
