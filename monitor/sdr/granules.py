"""What a reader gives: one typed object per granule (CrIS GEO and SDR, a VIIRS band's SDR and GEO), its
identity and provenance (:class:`GranuleMeta`), and the two places a granule file may lie
(:data:`GranuleRef`: a local path, or a :class:`RemoteGranule` read in place)."""

from __future__ import annotations

import datetime as dt
import io
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np


class RemoteGranule(Protocol):
    """A granule file read where it lies, a range at a time (``monitor.archive.ranged``): its base
    name (a JPSS file name), ``str()`` naming it in errors (its key), and a binary file object to read it
    through. When a read of that object fails, its ``failure`` says why (the transport's reason, naming the
    key)."""

    @property
    def name(self) -> str:  # numpydoc ignore=RT01
        """The granule's file name."""
        ...

    def open(self) -> io.RawIOBase:
        """A seekable binary file object over the granule's bytes."""
        ...


GranuleRef = Path | RemoteGranule  # a granule file: on local disk, or read in place


def as_ref(path: str | os.PathLike | RemoteGranule) -> GranuleRef:
    """A local path (str or PathLike) as a Path; a :class:`RemoteGranule` as it is.

    Parameters
    ----------
    path : str or os.PathLike or GranuleRef
        A file.

    Returns
    -------
    GranuleRef
        It, as the readers take it.
    """
    return Path(path) if isinstance(path, (str, os.PathLike)) else path


@dataclass(frozen=True)
class GranuleMeta:
    """What identifies a granule and what produced it (from the ``_Gran_k`` attributes)."""

    path: str
    product: str
    collection: str
    platform: str  # npp, j01, j02
    granule_id: str
    orbit: int
    start: dt.datetime
    end: dt.datetime
    start_iet_us: int
    end_iet_us: int
    n_scans: int
    ascending: bool | None
    software_version: str
    algorithm_version: str
    aux_files: tuple[str, ...]
    anc_files: tuple[str, ...]

    def to_dict(self) -> dict:
        d = dict(self.__dict__)
        d["start"] = self.start.isoformat()
        d["end"] = self.end.isoformat()
        d["aux_files"] = list(self.aux_files)
        d["anc_files"] = list(self.anc_files)
        return d


@dataclass
class CrisGeoGranule:
    """CrIS GEO arrays of one granule; FOV fields (nscan, 30, 9), per-FOR times (nscan, 30)."""

    meta: GranuleMeta
    for_time_us: np.ndarray
    start_time_us: np.ndarray
    mid_time_us: np.ndarray
    lat_rad: np.ndarray
    lon_rad: np.ndarray
    height_m: np.ndarray
    range_m: np.ndarray
    zenith_rad: np.ndarray
    azimuth_rad: np.ndarray
    sc_position_m: np.ndarray
    sc_velocity_m_s: np.ndarray
    sc_attitude_rad: np.ndarray

    @property
    def valid(self) -> np.ndarray:  # numpydoc ignore=RT01
        """FOVs whose every geometry field is present."""
        ok = np.ones(self.lat_rad.shape, bool)
        for a in (self.lat_rad, self.lon_rad, self.range_m, self.zenith_rad, self.azimuth_rad):
            ok &= np.isfinite(a)
        scan_ok = np.all(
            np.isfinite(self.sc_position_m)
            & np.isfinite(self.sc_velocity_m_s)
            & np.isfinite(self.sc_attitude_rad),
            axis=1,
        )
        return ok & scan_ok[:, None, None] & (self.for_time_us > 0)[:, :, None]


@dataclass
class CrisSdrGranule:
    """CrIS long-wave radiances (nscan, 30, 9, nchan) in mW/(m2 sr cm-1) and their quality; the short-wave
    ones where the file has them (VIIRS M13 lies in the SW band)."""

    meta: GranuleMeta
    wavenumber_cm1: np.ndarray
    radiance_lw: np.ndarray
    qf3: np.ndarray
    qf1_scan: np.ndarray | None
    radiance_sw: np.ndarray | None = None
    wavenumber_sw_cm1: np.ndarray | None = None

    @property
    def good(self) -> np.ndarray:  # numpydoc ignore=RT01
        """FOVs with good LW SDR quality (``QF3 & 0b11 == 0``, Wang's rule) and finite spectra."""
        ok = (self.qf3[..., 0] & 0b11) == 0
        return ok & np.all(np.isfinite(self.radiance_lw), axis=-1)


@dataclass
class ViirsSdrGranule:
    """A VIIRS band's brightness temperature (rows, columns) in K, NaN where filled (bow-tie deletion
    included); the band is its product's (``meta.product``: SVI05, SVM15, ...)."""

    meta: GranuleMeta
    bt_k: np.ndarray
    qf1: np.ndarray

    @property
    def good(self) -> np.ndarray:  # numpydoc ignore=RT01
        """Pixels with a value and QF1 == 0 (Wang's rule)."""
        return np.isfinite(self.bt_k) & (self.qf1 == 0)


@dataclass
class ViirsGeoGranule:
    """VIIRS geolocation of an I- or M-band grid (rows, columns) and per-scan spacecraft state.

    Each pixel is the 3-D point (lat_rad, lon_rad, height_m): GITCO and GMTCO give the terrain height where
    the pixel's line of sight meets the terrain, GIMGO and GMODO (ellipsoid geolocation) have no Height and
    their pixels are at h = 0 (``height_m`` zeros).
    """

    meta: GranuleMeta
    lat_rad: np.ndarray
    lon_rad: np.ndarray
    start_time_us: np.ndarray
    mid_time_us: np.ndarray
    sc_position_m: np.ndarray
    sc_velocity_m_s: np.ndarray
    sc_attitude_rad: np.ndarray
    height_m: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.height_m is None:
            self.height_m = np.zeros_like(self.lat_rad)


Granule = CrisGeoGranule | CrisSdrGranule | ViirsSdrGranule | ViirsGeoGranule
GeoGranule = CrisGeoGranule | ViirsGeoGranule

_GRANULE_TYPES: dict[str, type[Granule]] = {
    "cris_geo": CrisGeoGranule,
    "cris_sdr": CrisSdrGranule,
    "viirs_sdr": ViirsSdrGranule,
    "viirs_geo": ViirsGeoGranule,
}
