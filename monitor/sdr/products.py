"""The JPSS products the monitor reads, described as data (dataset paths, shapes, units, limits, fills).

Layout facts: docs/jpss-formats.md sections 1.2-1.8 (IDPS CDFCB layout, checked on real GCRSO files; satpy's
``viirs_sdr.yaml`` for the VIIRS names). Each field maps a Python name with its unit to a dataset of
``/All_Data/<collection>_All``:

* ``per``: what axis 0 counts: ``scan`` (CrIS arrays and VIIRS per-scan arrays) or ``row`` (VIIRS
  detector rows, ``rows_per_scan`` per scan).
* ``dims``: the shape after axis 0 (every axis is checked).
* ``kind``: ``float`` (float32/64; the IDPS float fills -999.9 ... -999.2 become NaN), ``scaled`` (uint16 with
  fills >= 65528, then ``value * scale + offset`` with one (scale, offset) pair per granule), ``time`` (int64
  IET microseconds) or ``flags`` (unsigned integers kept as they are).
* ``limits``: the physical range of every value that is not a fill, in the file's unit after scaling;
  ``norm``: the same for the length of a 3-vector (positions near the orbit radius).
* ``to_si``: factor to the unit in the field's name (degrees -> radians, arcseconds -> radians).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.bands import BANDS, GRIDS, ViirsGrid
from monitor.core.constants import N_FOR, N_FOV, VIIRS_SCANS

DEG = np.pi / 180.0
ARCSEC = np.pi / (180.0 * 3600.0)
FLOAT_FILLS = (
    -999.9,
    -999.8,
    -999.7,
    -999.6,
    -999.5,
    -999.4,
    -999.3,
    -999.2,
)  # IDPS float fills (NA ... SOUB)
UINT16_FILL_MIN = 65528  # IDPS uint16 fills are 65528 ... 65535


def is_float_fill(values: ArrayLike) -> np.ndarray:
    """True where *values* hold one of the IDPS float fill codes (not merely a large negative number).

    Parameters
    ----------
    values : array_like
        Float values.

    Returns
    -------
    numpy.ndarray
        bool, the shape of *values*.
    """
    v = np.asarray(values)
    with np.errstate(invalid="ignore", over="ignore"):
        fill = np.asarray(v < -999.15)
        if fill.any():  # the rest of the test on the few candidates only (granules are 10 million pixels)
            near = v[fill]
            fill[fill] = (near > -999.95) & (np.abs(near * 10 - np.round(near * 10)) < 1e-2)
    return fill


@dataclass(frozen=True)
class Field:
    """One dataset of a product: where it is, its shape after axis 0, its kind, unit and physical limits."""

    dataset: str
    per: str = "scan"
    kind: str = "float"
    to_si: float = 1.0
    factors: str | None = None
    required: bool = True
    dims: tuple = ()
    limits: tuple | None = None
    norm: tuple | None = None


IET_LIMITS_US = (1.6e15, 2.8e15)  # IET of 2008 ... 2046: a time outside is not a JPSS observation time


@dataclass(frozen=True)
class Product:
    """One JPSS product: file-name prefix, HDF5 collection, reader kind and its fields (a Field by name).

    A VIIRS product also names its grid (``resolution``, I or M) and, an SDR, its band (I5, M13, ...).
    """

    prefix: str
    collection: str
    kind: str
    rows_per_scan: int = 1
    scans_reserved: int | None = None  # VIIRS arrays always hold 48 scans per granule
    fields: dict = field(default_factory=dict)
    resolution: str | None = None
    band: str | None = None

    @property
    def data_group(self) -> str:  # numpydoc ignore=RT01
        """The HDF5 group that holds the product's arrays."""
        return f"All_Data/{self.collection}_All"


# CrIS long-wave grid: 717 channels from 648.75 cm-1 every 0.625 cm-1 (2 guard channels each end), NSR and
# FSR.
CRIS_LW_FIRST_CM1 = 648.75
CRIS_LW_STEP_CM1 = 0.625
CRIS_LW_CHANNELS = 717
FOV = (N_FOR, N_FOV)  # CrIS: 30 fields of regard of 9 FOVs per scan
CRIS_GEO_FIELDS = {
    "for_time_us": Field("FORTime", kind="time", dims=(N_FOR,), limits=IET_LIMITS_US),
    "start_time_us": Field("StartTime", kind="time", limits=IET_LIMITS_US),
    "mid_time_us": Field("MidTime", kind="time", limits=IET_LIMITS_US),
    "lat_rad": Field("Latitude", to_si=DEG, dims=FOV, limits=(-90.0, 90.0)),
    "lon_rad": Field("Longitude", to_si=DEG, dims=FOV, limits=(-180.0, 180.0)),
    "height_m": Field("Height", dims=FOV, limits=(-500.0, 9000.0)),
    "range_m": Field("SatelliteRange", dims=FOV, limits=(7.0e5, 4.0e6)),
    "zenith_rad": Field("SatelliteZenithAngle", to_si=DEG, dims=FOV, limits=(0.0, 90.0)),
    "azimuth_rad": Field("SatelliteAzimuthAngle", to_si=DEG, dims=FOV, limits=(-180.0, 360.0)),
    "sc_position_m": Field("SCPosition", dims=(3,), norm=(6.8e6, 7.8e6)),
    "sc_velocity_m_s": Field("SCVelocity", dims=(3,), norm=(6.0e3, 8.5e3)),
    "sc_attitude_rad": Field("SCAttitude", to_si=ARCSEC, dims=(3,), limits=(-3600.0, 3600.0)),
}

# CrIS short-wave grid (VIIRS M13 lies in it): 2155-2550 cm-1 with 2 guard channels each end, 0.625 cm-1
# apart in full spectral resolution (637 stored), 2.5 cm-1 in normal (163 stored)
CRIS_SW_FIRST_CM1 = 2155.0
CRIS_SW_STEP_CM1 = {"SCRIF": 0.625, "SCRIS": 2.5}
CRIS_SW_CHANNELS = {"SCRIF": 637, "SCRIS": 163}


def _cris_sdr_fields(prefix: str) -> dict:
    """The CrIS SDR fields of a product: the LW spectra, the SW spectra (optional: only M13 needs them)."""
    return {
        "radiance_lw": Field(
            "ES_RealLW", dims=FOV + (CRIS_LW_CHANNELS,), limits=(-200.0, 500.0)
        ),  # mW/(m2 sr cm-1)
        "radiance_sw": Field(
            "ES_RealSW", dims=FOV + (CRIS_SW_CHANNELS[prefix],), limits=(-20.0, 20.0), required=False
        ),  # mW/(m2 sr cm-1)
        "qf3": Field("QF3_CRISSDR", kind="flags", dims=FOV + (3,)),
        "qf1_scan": Field("QF1_SCAN_CRISSDR", kind="flags", required=False),
    }


def _viirs_sdr_fields(band: str) -> dict:
    """A VIIRS band's SDR fields: its brightness temperature (uint16 and factors, or float32) and quality."""
    b = BANDS[band]
    cols = (b.grid.columns,)
    bt = (
        Field("BrightnessTemperature", per="row", kind="scaled", factors="BrightnessTemperatureFactors")
        if b.bt_scaled
        else Field("BrightnessTemperature", per="row")
    )
    return {
        "bt_k": Field(bt.dataset, bt.per, bt.kind, factors=bt.factors, dims=cols, limits=(120.0, 380.0)),
        "qf1": Field(b.quality_dataset, per="row", kind="flags", dims=cols),
    }


def _viirs_geo_fields(grid: ViirsGrid, terrain: bool) -> dict:
    """A VIIRS grid's GEO fields. Terrain-corrected geolocation: Latitude/Longitude/Height is the 3-D point
    where the pixel's line of sight meets the terrain (docs/jpss-formats.md 1.8); the ellipsoid product
    (GIMGO, GMODO) puts its pixels at h = 0."""
    cols = (grid.columns,)
    fields = {
        "lat_rad": Field("Latitude", per="row", to_si=DEG, dims=cols, limits=(-90.0, 90.0)),
        "lon_rad": Field("Longitude", per="row", to_si=DEG, dims=cols, limits=(-180.0, 180.0)),
        "start_time_us": Field("StartTime", kind="time", limits=IET_LIMITS_US),
        "mid_time_us": Field("MidTime", kind="time", limits=IET_LIMITS_US),
        "sc_position_m": Field("SCPosition", dims=(3,), norm=(6.8e6, 7.8e6)),
        "sc_velocity_m_s": Field("SCVelocity", dims=(3,), norm=(6.0e3, 8.5e3)),
        "sc_attitude_rad": Field("SCAttitude", to_si=ARCSEC, dims=(3,), limits=(-3600.0, 3600.0)),
    }
    if terrain:
        fields["height_m"] = Field("Height", per="row", dims=cols)
    return fields


def _viirs_products() -> tuple[Product, ...]:
    """Per band its SDR product, per grid its GEO products (terrain corrected first), from the band table."""
    out = [
        Product(
            b.sdr_prefix,
            b.sdr_collection,
            "viirs_sdr",
            rows_per_scan=b.grid.detectors,
            scans_reserved=VIIRS_SCANS,
            fields=_viirs_sdr_fields(b.name),
            resolution=b.resolution,
            band=b.name,
        )
        for b in BANDS.values()
    ]
    for g in GRIDS.values():
        for k, (prefix, collection) in enumerate(zip(g.geo_prefixes, g.geo_collections, strict=True)):
            out.append(
                Product(
                    prefix,
                    collection,
                    "viirs_geo",
                    rows_per_scan=g.detectors,
                    scans_reserved=VIIRS_SCANS,
                    fields=_viirs_geo_fields(g, terrain=k == 0),
                    resolution=g.resolution,
                )
            )
    return tuple(out)


# The product table. Within a kind the first listed is preferred (full spectral resolution; terrain-corrected
# geolocation, the only one NOAA's archive carries). The collection is also the product's NODD folder.
PRODUCTS = {
    p.prefix: p
    for p in (
        Product("SCRIF", "CrIS-FS-SDR", "cris_sdr", fields=_cris_sdr_fields("SCRIF")),
        Product("SCRIS", "CrIS-SDR", "cris_sdr", fields=_cris_sdr_fields("SCRIS")),
        Product("GCRSO", "CrIS-SDR-GEO", "cris_geo", fields=CRIS_GEO_FIELDS),
        *_viirs_products(),
    )
}


def prefixes(kind: str, band: str | None = None) -> tuple[str, ...]:
    """The prefixes of the products of *kind* (cris_sdr, cris_geo, viirs_sdr, viirs_geo), preferred first;
    for VIIRS, those of one band (its SDR) or of the band's grid (its GEO).

    Parameters
    ----------
    kind : str
        A granule kind (``cris_geo``, ``viirs_sdr``, ...).
    band : str, optional
        A VIIRS band (I5, M13, M15, M16).

    Returns
    -------
    tuple of str
        Its products' prefixes.
    """
    if band is None:
        return tuple(p.prefix for p in PRODUCTS.values() if p.kind == kind)
    b = BANDS[band]
    return tuple(
        p.prefix
        for p in PRODUCTS.values()
        if p.kind == kind and p.resolution == b.resolution and p.band in (None, band)
    )


CRIS_SDR, CRIS_GEO = prefixes("cris_sdr"), prefixes("cris_geo")
# the assessment's VIIRS products: I5 and the I-band geolocation
VIIRS_SDR, VIIRS_GEO = prefixes("viirs_sdr", "I5"), prefixes("viirs_geo", "I5")
CRIS_PRODUCTS = CRIS_SDR + CRIS_GEO


def cris_sw_wavenumbers_cm1(nchan: int = CRIS_SW_CHANNELS["SCRIF"]) -> np.ndarray:
    """Wavenumbers (cm-1) of the stored CrIS SW channels: full spectral resolution (637) or normal (163).

    Parameters
    ----------
    nchan : int, optional
        The SW channels stored.

    Returns
    -------
    numpy.ndarray
        cm-1.
    """
    step = next((CRIS_SW_STEP_CM1[p] for p, n in CRIS_SW_CHANNELS.items() if n == nchan), None)
    if step is None:
        raise ValueError(f"{nchan} SW channels: not one of {sorted(CRIS_SW_CHANNELS.values())}")
    return CRIS_SW_FIRST_CM1 - 2 * step + step * np.arange(nchan)


def cris_lw_wavenumbers_cm1(nchan: int = CRIS_LW_CHANNELS) -> np.ndarray:
    """Wavenumbers (cm-1) of the stored CrIS LW channels.

    Parameters
    ----------
    nchan : int, optional
        The LW channels.

    Returns
    -------
    numpy.ndarray
        cm-1.
    """
    return CRIS_LW_FIRST_CM1 + CRIS_LW_STEP_CM1 * np.arange(nchan)
