"""Spectral matching of CrIS to a VIIRS band (I5, M13, M15, M16): SRF convolution and band-Planck BT.

CrIS radiance R(nu) in mW/(m2 sr cm-1) is apodized (Hamming 0.23/0.54/0.23, as Wang's code does),
integrated with the band's response S(nu) sampled on the CrIS grid of the CrIS band that holds it (LW for
I5, M15 and M16; SW for M13): L = sum R S / sum S, and turned into a brightness temperature with the
band-integrated Planck function of the same response, inverted through a fine table. The response is cut
to the CrIS band (what lies outside it is not measured by CrIS). The same band model turns a VIIRS pixel
BT into band radiance, so both sides are averaged in radiance. Responses: ``monitor/data/srf`` (NOAA/NG
release; NOAA-21 has none public, NOAA-20's are used).
"""

from __future__ import annotations

import math
from functools import lru_cache
from importlib import resources

import numba
import numpy as np
from numpy.typing import ArrayLike

from monitor.compiled.threads import KERNEL_LOCK
from monitor.core.bands import BANDS
from monitor.core.errors import DataError
from monitor.core.satellites import SATELLITES
from monitor.sdr.products import cris_lw_wavenumbers_cm1, cris_sw_wavenumbers_cm1

C1 = 1.191042972e-5  # 2hc^2, mW/(m2 sr cm-4)
C2 = 1.4387769  # hc/k, cm K
HAMMING = (0.23, 0.54, 0.23)
GUESS_BINS = 4096  # the inverse table's index is guessed from a uniform grid of radiance
PARALLEL_FROM = 1 << 16  # values converted at once from which the parallel kernel is worth its lock


@numba.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _interp_one(v: float, xp: np.ndarray, fp: np.ndarray, guess: np.ndarray) -> float:
    """``np.interp(v, xp, fp, left=NaN, right=NaN)`` bit for bit (the same slope and fall-backs). *xp*
    ascends; guess[k] is at most the index of the last xp <= v for every v in the k-th of the uniform bins
    between xp[0] and xp[-1], so a few steps find it."""
    n = xp.shape[0]
    if not (v >= xp[0] and v <= xp[n - 1]):  # NaN, or outside the table
        return np.nan
    nb = guess.shape[0] - 1
    j = guess[min(int((v - xp[0]) * (nb / (xp[n - 1] - xp[0]))), nb)]
    while j + 1 < n and xp[j + 1] <= v:
        j += 1
    if j == n - 1 or xp[j] == v:
        return fp[j]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    r = slope * (v - xp[j]) + fp[j]
    if math.isnan(r):
        r = slope * (v - xp[j + 1]) + fp[j + 1]
        if math.isnan(r) and fp[j] == fp[j + 1]:
            r = fp[j]
    return r


@numba.njit(cache=True, nogil=True, error_model="numpy", parallel=True)
def _interp_parallel(
    x: np.ndarray, xp: np.ndarray, fp: np.ndarray, guess: np.ndarray, out: np.ndarray
) -> None:
    """:func:`_interp_one` of every value of flat *x* into *out*, in parallel."""
    for i in numba.prange(x.shape[0]):
        out[i] = _interp_one(x[i], xp, fp, guess)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _interp_serial(x: np.ndarray, xp: np.ndarray, fp: np.ndarray, guess: np.ndarray, out: np.ndarray) -> None:
    """:func:`_interp_one` of every value of flat *x* into *out*, on the calling thread."""
    for i in range(x.shape[0]):
        out[i] = _interp_one(x[i], xp, fp, guess)


def planck_radiance(wavenumber_cm1: ArrayLike, t_k: ArrayLike) -> np.ndarray:
    """Planck radiance at a wavenumber and temperature.

    Parameters
    ----------
    wavenumber_cm1 : array_like
        cm-1.
    t_k : array_like
        Temperature, K, broadcast against the wavenumbers.

    Returns
    -------
    numpy.ndarray
        mW/(m2 sr cm-1).
    """
    nu = np.asarray(wavenumber_cm1, float)
    return C1 * nu**3 / np.expm1(C2 * nu / np.asarray(t_k, float))


def srf_file(satellite: str, band: str = "I5") -> str:
    """The file of a satellite's VIIRS band response in ``monitor/data/srf``.

    Parameters
    ----------
    satellite : str
        ``npp``, ``j01`` or ``j02`` (NOAA-21 uses NOAA-20's).
    band : str, optional
        I5, M13, M15 or M16.

    Returns
    -------
    str
        The file name.
    """
    if satellite not in SATELLITES:
        raise DataError(
            f"no {band} spectral response for satellite {satellite!r} (known: {', '.join(SATELLITES)})"
        )
    if band not in BANDS:
        raise DataError(f"no spectral response for band {band!r} (known: {', '.join(BANDS)})")
    return f"{SATELLITES[satellite].srf_platform}_viirs_{BANDS[band].srf_tag}_srf.csv"


def load_srf(satellite: str, band: str = "I5") -> tuple[np.ndarray, np.ndarray]:
    """The VIIRS relative spectral response of a satellite's band.

    Parameters
    ----------
    satellite : str
        ``npp``, ``j01`` or ``j02`` (NOAA-21 uses NOAA-20's).
    band : str, optional
        I5, M13, M15 or M16.

    Returns
    -------
    wavenumber_cm1, response : numpy.ndarray
        Ascending wavenumbers, cm-1, and the relative response.
    """
    name = srf_file(satellite, band)
    text = resources.files("monitor.data.srf").joinpath(name).read_text()
    data = _read_csv(text)
    order = np.argsort(data[:, 0])
    return data[order, 0], data[order, 1]


def _read_csv(text: str) -> np.ndarray:
    rows = [line.split(",") for line in text.splitlines() if line and not line.startswith("#")]
    return np.array([[float(a), float(b)] for a, b in rows[1:]])


def apodize_hamming(radiance: ArrayLike) -> np.ndarray:
    """Hamming apodization along the last (channel) axis; the end channels keep their value.

    Parameters
    ----------
    radiance : array_like
        Spectra, channels last.

    Returns
    -------
    numpy.ndarray
        The apodized spectra, same unit and shape.
    """
    r = np.asarray(radiance)
    out = r.copy()
    out[..., 1:-1] = HAMMING[0] * r[..., :-2] + HAMMING[1] * r[..., 1:-1] + HAMMING[2] * r[..., 2:]
    return out


class BandModel:
    """A VIIRS band of one satellite sampled on a CrIS grid, with its band-Planck table.

    Parameters
    ----------
    satellite : str
        ``npp``, ``j01`` or ``j02`` (its relative spectral response, :func:`load_srf`).
    wavenumber_cm1 : array_like, optional
        The grid the response is sampled on, cm-1; by default the channels of the CrIS band that holds the
        VIIRS band (LW; SW in full spectral resolution for M13).
    band : str, optional
        I5, M13, M15 or M16.
    """

    T_MIN_K, T_MAX_K, T_STEP_K = 150.0, 350.0, 0.02

    def __init__(self, satellite: str, wavenumber_cm1: ArrayLike | None = None, band: str = "I5") -> None:
        self.satellite = satellite
        self.band = band
        self.cris_band = BANDS[band].cris_band if band in BANDS else "LW"
        default = cris_sw_wavenumbers_cm1 if self.cris_band == "SW" else cris_lw_wavenumbers_cm1
        self.wavenumber_cm1 = default() if wavenumber_cm1 is None else np.asarray(wavenumber_cm1)
        nu, s = load_srf(satellite, band)
        self.response = np.interp(self.wavenumber_cm1, nu, s, left=0.0, right=0.0)
        self.weights = self.response / self.response.sum()
        self._t = np.arange(self.T_MIN_K, self.T_MAX_K + self.T_STEP_K / 2, self.T_STEP_K)
        self._l = planck_radiance(self.wavenumber_cm1[None, :], self._t[:, None]) @ self.weights
        edges = np.linspace(self._l[0], self._l[-1], GUESS_BINS + 1)  # one below, for the edge's rounding
        self._guess = np.maximum(np.searchsorted(self._l, edges, "right") - 2, 0)

    def band_radiance(self, spectra: ArrayLike) -> np.ndarray:
        """The band radiance of spectra on the CrIS LW grid.

        Parameters
        ----------
        spectra : array_like
            Spectral radiance, mW/(m2 sr cm-1), channels last.

        Returns
        -------
        numpy.ndarray
            Band radiance, mW/(m2 sr cm-1).
        """
        return np.asarray(spectra) @ self.weights

    def cris_band_radiance(self, radiance: ArrayLike) -> np.ndarray:
        """The band radiance of unapodized CrIS spectra on :attr:`wavenumber_cm1`: Hamming apodization,
        then the SRF convolution.

        Parameters
        ----------
        radiance : array_like
            CrIS spectral radiance (LW, or SW for M13), mW/(m2 sr cm-1), channels last.

        Returns
        -------
        numpy.ndarray
            Band radiance, mW/(m2 sr cm-1).
        """
        return self.band_radiance(apodize_hamming(radiance))

    @property
    def radiance_table(self) -> tuple[float, float, np.ndarray]:
        """The uniform table :meth:`radiance_from_bt` interpolates.

        Returns
        -------
        t_min_k, t_step_k : float
            The first BT and the step, K.
        table : numpy.ndarray
            Band radiance per BT, mW/(m2 sr cm-1).
        """
        return self.T_MIN_K, self.T_STEP_K, self._l

    def radiance_from_bt(self, bt_k: ArrayLike) -> np.ndarray:
        """The band radiance of a band brightness temperature.

        The table is uniform in temperature, so the interpolation is index arithmetic.

        Parameters
        ----------
        bt_k : array_like
            BT, K.

        Returns
        -------
        numpy.ndarray
            mW/(m2 sr cm-1); NaN outside 150-350 K.
        """
        x = (np.asarray(bt_k, np.float64) - self.T_MIN_K) / self.T_STEP_K
        with np.errstate(invalid="ignore"):
            ok = (x >= 0) & (x <= len(self._t) - 1)
        i = np.clip(np.where(ok, x, 0).astype(np.intp), 0, len(self._t) - 2)
        w = x - i
        return np.where(ok, self._l[i] * (1 - w) + self._l[i + 1] * w, np.nan)

    def bt_from_radiance(self, radiance: ArrayLike) -> np.ndarray:
        """The band brightness temperature of a band radiance.

        The table is inverted by linear interpolation (np.interp's numbers, compiled and in parallel: an
        assessment converts ten million cone means).

        Parameters
        ----------
        radiance : array_like
            Band radiance, mW/(m2 sr cm-1).

        Returns
        -------
        numpy.ndarray
            BT, K, float64, the shape of *radiance*; NaN outside the table.
        """
        x = np.ravel(np.asarray(radiance, np.float64))
        shape = np.shape(radiance)
        out = np.empty(shape)
        if x.size >= PARALLEL_FROM:
            with KERNEL_LOCK:
                _interp_parallel(x, self._l, self._t, self._guess, out.reshape(-1))
        else:  # a CrIS granule's 1080 FOVs: no lock to wait for beside a running kernel
            _interp_serial(x, self._l, self._t, self._guess, out.reshape(-1))
        return out if shape else out[()]


@lru_cache(maxsize=32)
def band_model(
    satellite: str, band: str = "I5", wavenumber_cm1: tuple[float, ...] | None = None
) -> BandModel:
    """The cached :class:`BandModel` of a satellite's band.

    Parameters
    ----------
    satellite : str
        ``npp``, ``j01`` or ``j02``.
    band : str, optional
        I5, M13, M15 or M16.
    wavenumber_cm1 : tuple of float, optional
        The CrIS grid, cm-1 (a tuple: it is a cache key); the band's CrIS band in full resolution by default.

    Returns
    -------
    BandModel
        The band.
    """
    return BandModel(satellite, None if wavenumber_cm1 is None else np.asarray(wavenumber_cm1), band)


def i5_band(satellite: str) -> BandModel:
    """The cached I5 :class:`BandModel` of a satellite (the assessment's band).

    Parameters
    ----------
    satellite : str
        ``npp``, ``j01`` or ``j02``.

    Returns
    -------
    BandModel
        The band.
    """
    return band_model(satellite, "I5")
