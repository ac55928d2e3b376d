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

Spectra add a simple atmosphere: R(nu) = tau(nu) B(nu, T) + (1 - tau(nu)) B(nu, T_atm).
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.typing import ArrayLike

from monitor.instrument.spectral import planck_radiance

EARTH_RADIUS_KM = 6371.0
FINE_KM, FINE_N = 1.1, 2048
COARSE_KM, COARSE_N = 4.4, 512
T_ATM_K = 262.0
LAPSE_K_PER_M = 6.5e-3
LAND_DAY_K, LAND_NIGHT_K = 6.0, -5.0
MAX_SLOPE = 0.4
MAX_HEIGHT_M = 4000.0
CLOUD_PER_M = 0.15e-3  # more cloud over high ground: the cloud field's threshold drops 0.15 per km


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


@numba.njit(cache=True, nogil=True)
def _triplanar_samples(
    x: np.ndarray, y: np.ndarray, z: np.ndarray, flat: np.ndarray, n: int, scale: float, out: np.ndarray
) -> None:
    """out (P, C) = the triplanar blend at unit vectors (x, y, z) (P,) of the fields *flat* (3, n * n, C):
    for each plane the bilinear sample at the point's two in-plane coordinates (times *scale*), weighted
    by the fourth power of the direction cosine normal to the plane over their root sum of squares.
    One pass per point: the arithmetic of the array form, without its (P, C) temporaries."""
    mask = n - 1  # n is a power of two: modulo by mask
    nc = flat.shape[2]
    for k in range(x.shape[0]):
        c = (x[k], y[k], z[k])
        w = (c[0] ** 4, c[1] ** 4, c[2] ** 4)
        norm = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
        for ch in range(nc):
            out[k, ch] = 0.0
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
                out[k, ch] += a * wp


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


class Scene:
    """Emitting temperature and terrain of the synthetic Earth.

    ``temperature_k(lat_rad, lon_rad, height_m)`` and ``height_m(lat_rad, lon_rad)`` (zero without
    *terrain*); *night* makes land colder than the sea instead of warmer.
    """

    def __init__(
        self,
        seed: int = 0,
        cloud_fraction: float = 0.45,
        land_fraction: float = 0.3,
        terrain: bool = False,
        night: bool = False,
    ):
        rng = np.random.default_rng(seed)
        self.terrain = terrain
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
        """Terrain height (m): a coastal ramp times ranges (ridged noise) on plateaus (a squashed field)."""
        coast = np.clip((land - self.land_threshold) / 1.0, 0.0, 1.0)
        coast = coast * coast * (3 - 2 * coast)  # smoothstep: no cliff at the shore
        plateau = 2200.0 + 1300.0 * np.tanh(1.2 * relief)
        ridge = 700.0 * (1.0 - np.abs(np.tanh(ridges)))
        return (coast * np.minimum(plateau + ridge, MAX_HEIGHT_M) * self.relief_gain).astype(np.float32)

    def _max_slope(self) -> float:
        """Largest terrain slope on a 1 km probe grid over a few thousand km (the field is stationary)."""
        step_rad = 1.0 / EARTH_RADIUS_KM
        lat = np.arange(-0.15, 0.15, step_rad)
        lat, lon = np.meshgrid(lat, np.arange(0.0, 0.3, step_rad), indexing="ij")
        h = self._height(*np.moveaxis(self.shape(_unit_vectors(lat, lon)), -1, 0))
        gy, gx = np.gradient(h, 1000.0)
        return float(np.max(np.hypot(gx, gy)))

    def height_m(self, lat_rad: ArrayLike, lon_rad: ArrayLike) -> np.ndarray:
        """Terrain height (m) above the ellipsoid at geodetic *lat_rad*, *lon_rad*; float32."""
        if not self.terrain:
            return np.zeros(np.shape(lat_rad), np.float32)
        return self._height(*np.moveaxis(self.shape(_unit_vectors(lat_rad, lon_rad)), -1, 0))

    def temperature_k(
        self, lat_rad: ArrayLike, lon_rad: ArrayLike, height_m: ArrayLike | None = None
    ) -> np.ndarray:
        """Emitting temperature (K) at geodetic *lat_rad*, *lon_rad* and terrain height *height_m*."""
        xyz = _unit_vectors(lat_rad, lon_rad)
        land = self.shape(xyz)[..., 0]
        top, texture = np.moveaxis(self.surface(xyz), -1, 0)
        h = np.zeros(np.shape(lat_rad), np.float32) if height_m is None else np.asarray(height_m, np.float32)
        sst = (301.0 - 12.0 * np.sin(np.asarray(lat_rad)) ** 2).astype(np.float32)
        land_frac = np.clip((land - self.land_threshold) / 0.05, 0.0, 1.0)
        surface = sst + land_frac * (self.land_offset_k + 3.0 * texture) - LAPSE_K_PER_M * h
        top = 245.0 + 18.0 * top
        cloud = self.cloud(xyz)[..., 0]
        cover = np.clip((cloud - self.cloud_threshold + CLOUD_PER_M * h) / 0.6, 0.0, 1.0)
        return (surface * (1 - cover) + np.minimum(top, surface) * cover).astype(np.float32)


def transmittance(wavenumber_cm1: ArrayLike) -> np.ndarray:
    """A simple clear-sky transmittance: a moist window with CO2 below 760 cm-1 and ozone near 1040 cm-1."""
    nu = np.asarray(wavenumber_cm1, float)
    k = 0.12 + 0.25 * ((nu - 900.0) / 150.0) ** 2
    k += 4.0 / (1.0 + np.exp((nu - 740.0) / 8.0))
    k += 1.2 * np.exp(-0.5 * ((nu - 1042.0) / 18.0) ** 2)
    k += 0.08 * (1.0 + np.sin(nu * 2.1)) * np.exp(-0.5 * ((nu - 870.0) / 120.0) ** 2)
    return np.exp(-k)


def spectra(wavenumber_cm1: ArrayLike, mean_planck: ArrayLike) -> np.ndarray:
    """Top-of-atmosphere spectra from the cone-mean surface Planck radiance (..., nchan)."""
    tau = transmittance(wavenumber_cm1)
    return tau * mean_planck + (1.0 - tau) * planck_radiance(wavenumber_cm1, T_ATM_K)
