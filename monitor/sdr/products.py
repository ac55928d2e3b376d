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

from monitor.core.constants import N_FOR, N_FOV, VIIRS_COLUMNS, VIIRS_DETECTORS, VIIRS_SCANS

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


DTYPES = {"float": "f", "scaled": "u", "time": "i", "flags": "u"}  # numpy kind of each field kind
IET_LIMITS_US = (1.6e15, 2.8e15)  # IET of 2008 ... 2046: a time outside is not a JPSS observation time


@dataclass(frozen=True)
class Product:
    """One JPSS product: file-name prefix, HDF5 collection, reader kind and its fields (a Field by name)."""

    prefix: str
    collection: str
    kind: str
    rows_per_scan: int = 1
    scans_reserved: int | None = None  # VIIRS arrays always hold 48 scans per granule
    fields: dict = field(default_factory=dict)

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

CRIS_SDR_FIELDS = {
    "radiance_lw": Field(
        "ES_RealLW", dims=FOV + (CRIS_LW_CHANNELS,), limits=(-200.0, 500.0)
    ),  # mW/(m2 sr cm-1)
    "qf3": Field("QF3_CRISSDR", kind="flags", dims=FOV + (3,)),
    "qf1_scan": Field("QF1_SCAN_CRISSDR", kind="flags", required=False),
}

VIIRS_SDR_FIELDS = {
    "bt_k": Field(
        "BrightnessTemperature",
        per="row",
        kind="scaled",
        factors="BrightnessTemperatureFactors",
        dims=(VIIRS_COLUMNS,),
        limits=(120.0, 380.0),
    ),
    "qf1": Field("QF1_VIIRSIBANDSDR", per="row", kind="flags", dims=(VIIRS_COLUMNS,)),
}

VIIRS_GEO_FIELDS = {
    "lat_rad": Field("Latitude", per="row", to_si=DEG, dims=(VIIRS_COLUMNS,), limits=(-90.0, 90.0)),
    "lon_rad": Field("Longitude", per="row", to_si=DEG, dims=(VIIRS_COLUMNS,), limits=(-180.0, 180.0)),
    "start_time_us": Field("StartTime", kind="time", limits=IET_LIMITS_US),
    "mid_time_us": Field("MidTime", kind="time", limits=IET_LIMITS_US),
    "sc_position_m": Field("SCPosition", dims=(3,), norm=(6.8e6, 7.8e6)),
    "sc_velocity_m_s": Field("SCVelocity", dims=(3,), norm=(6.0e3, 8.5e3)),
    "sc_attitude_rad": Field("SCAttitude", to_si=ARCSEC, dims=(3,), limits=(-3600.0, 3600.0)),
}

# Terrain-corrected geolocation: Latitude/Longitude/Height is the 3-D point where the pixel's line of sight
# meets the terrain (docs/jpss-formats.md 1.8); the ellipsoid product (GIMGO) puts its pixels at h = 0.
VIIRS_TC_GEO_FIELDS = {**VIIRS_GEO_FIELDS, "height_m": Field("Height", per="row", dims=(VIIRS_COLUMNS,))}

# The product table. Within a kind the first listed is preferred (full spectral resolution; terrain-corrected
# geolocation, the only one NOAA's archive carries). The collection is also the product's NODD folder.
PRODUCTS = {
    p.prefix: p
    for p in (
        Product("SCRIF", "CrIS-FS-SDR", "cris_sdr", fields=CRIS_SDR_FIELDS),
        Product("SCRIS", "CrIS-SDR", "cris_sdr", fields=CRIS_SDR_FIELDS),
        Product("GCRSO", "CrIS-SDR-GEO", "cris_geo", fields=CRIS_GEO_FIELDS),
        Product(
            "SVI05",
            "VIIRS-I5-SDR",
            "viirs_sdr",
            rows_per_scan=VIIRS_DETECTORS,
            scans_reserved=VIIRS_SCANS,
            fields=VIIRS_SDR_FIELDS,
        ),
        Product(
            "GITCO",
            "VIIRS-IMG-GEO-TC",
            "viirs_geo",
            rows_per_scan=VIIRS_DETECTORS,
            scans_reserved=VIIRS_SCANS,
            fields=VIIRS_TC_GEO_FIELDS,
        ),
        Product(
            "GIMGO",
            "VIIRS-IMG-GEO",
            "viirs_geo",
            rows_per_scan=VIIRS_DETECTORS,
            scans_reserved=VIIRS_SCANS,
            fields=VIIRS_GEO_FIELDS,
        ),
    )
}


def prefixes(kind: str) -> tuple[str, ...]:
    """The prefixes of the products of *kind* (cris_sdr, cris_geo, viirs_sdr, viirs_geo), preferred first.

    Parameters
    ----------
    kind : str
        A granule kind (``cris_geo``, ``viirs_sdr``, ...).

    Returns
    -------
    tuple of str
        Its products' prefixes.
    """
    return tuple(p.prefix for p in PRODUCTS.values() if p.kind == kind)


CRIS_SDR, CRIS_GEO, VIIRS_SDR, VIIRS_GEO = (
    prefixes(k) for k in ("cris_sdr", "cris_geo", "viirs_sdr", "viirs_geo")
)
CRIS_PRODUCTS = CRIS_SDR + CRIS_GEO


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
