"""A synthetic Earth in the thermal infrared: ocean, coastlines and broken cloud, deterministic by seed.

The scene is an emitting temperature T(lat, lon) (K): sea-surface temperature falling with latitude,
land with its own temperature and texture, and clouds whose tops are colder, mixed by a cloud fraction
with soft edges. Fields are periodic random fields on a 0.01 deg grid (period ~41 deg), so any orbit
segment sees clouds at scales from ~2 km to hundreds of km. Spectra add a simple atmosphere:
R(nu) = tau(nu) B(nu, T) + (1 - tau(nu)) B(nu, T_atm).
"""

from __future__ import annotations

import numpy as np

from monitor.spectral import planck_radiance

GRID_DEG = 0.01
GRID_N = 4096
T_ATM_K = 262.0


def _random_field(rng, n, slope, low_cut):
    """Zero-mean unit-variance periodic field with power spectrum ~ k^-slope above *low_cut* cycles."""
    kx = np.fft.fftfreq(n) * n
    ky = np.fft.rfftfreq(n) * n
    k = np.hypot(kx[:, None], ky[None, :])
    amp = np.where(k >= low_cut, np.maximum(k, 1.0) ** (-slope / 2.0), 0.0)
    spec = amp * (rng.standard_normal(k.shape) + 1j * rng.standard_normal(k.shape))
    f = np.fft.irfft2(spec, s=(n, n))
    return ((f - f.mean()) / f.std()).astype(np.float32)


class Scene:
    """Emitting temperature of the synthetic Earth; ``temperature_k(lat_rad, lon_rad)``."""

    def __init__(self, seed: int = 0, cloud_fraction: float = 0.45, land_fraction: float = 0.3):
        rng = np.random.default_rng(seed)
        self.cloud = _random_field(rng, GRID_N, slope=3.2, low_cut=4)
        small = GRID_N // 4
        self.land = _random_field(rng, small, slope=3.6, low_cut=2)
        self.top = _random_field(rng, small, slope=3.0, low_cut=2)
        self.texture = _random_field(rng, small, slope=2.5, low_cut=2)
        self.cloud_threshold = float(np.quantile(self.cloud[::8, ::8], 1.0 - cloud_fraction))
        self.land_threshold = float(np.quantile(self.land[::4, ::4], 1.0 - land_fraction))

    @staticmethod
    def _weights(n, lat_rad, lon_rad, cell_deg):
        y = np.asarray(lat_rad, np.float64) * (180.0 / np.pi / cell_deg)
        x = np.asarray(lon_rad, np.float64) * (180.0 / np.pi / cell_deg)
        y0 = np.floor(y)
        x0 = np.floor(x)
        fy = (y - y0).astype(np.float32)
        fx = (x - x0).astype(np.float32)
        i0 = y0.astype(np.int64) % n
        j0 = x0.astype(np.int64) % n
        return i0 * n + j0, i0 * n + (j0 + 1) % n, ((i0 + 1) % n) * n + j0, ((i0 + 1) % n) * n + (j0 + 1) % n, fy, fx

    @staticmethod
    def _sample(field, w):
        a, b, c, d, fy, fx = w
        f = field.ravel()
        return (f[a] * (1 - fx) + f[b] * fx) * (1 - fy) + (f[c] * (1 - fx) + f[d] * fx) * fy

    def temperature_k(self, lat_rad, lon_rad):
        """Emitting temperature (K) at geodetic *lat_rad*, *lon_rad*; float32, same shape."""
        coarse = GRID_DEG * GRID_N / self.land.shape[0]
        wc = self._weights(self.land.shape[0], lat_rad, lon_rad, coarse)
        sst = (301.0 - 12.0 * np.sin(np.asarray(lat_rad)) ** 2).astype(np.float32)
        land_frac = np.clip((self._sample(self.land, wc) - self.land_threshold) / 0.05, 0.0, 1.0)
        surface = sst + land_frac * (6.0 + 3.0 * self._sample(self.texture, wc))
        top = 245.0 + 18.0 * self._sample(self.top, wc)
        del wc
        cover = np.clip((self._sample(self.cloud, self._weights(GRID_N, lat_rad, lon_rad, GRID_DEG))
                         - self.cloud_threshold) / 0.6, 0.0, 1.0)
        return (surface * (1 - cover) + np.minimum(top, surface) * cover).astype(np.float32)


def transmittance(wavenumber_cm1):
    """A simple clear-sky transmittance: a moist window with CO2 below 760 cm-1 and ozone near 1040 cm-1."""
    nu = np.asarray(wavenumber_cm1, float)
    k = 0.12 + 0.25 * ((nu - 900.0) / 150.0) ** 2
    k += 4.0 / (1.0 + np.exp((nu - 740.0) / 8.0))
    k += 1.2 * np.exp(-0.5 * ((nu - 1042.0) / 18.0) ** 2)
    k += 0.08 * (1.0 + np.sin(nu * 2.1)) * np.exp(-0.5 * ((nu - 870.0) / 120.0) ** 2)
    return np.exp(-k)


def spectra(wavenumber_cm1, mean_planck):
    """Top-of-atmosphere spectra from the cone-mean surface Planck radiance (..., nchan)."""
    tau = transmittance(wavenumber_cm1)
    return tau * mean_planck + (1.0 - tau) * planck_radiance(wavenumber_cm1, T_ATM_K)
