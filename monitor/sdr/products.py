"""The JPSS products the monitor reads, described as data (dataset paths, units, fill handling).

Layout facts: formats.md sections 1.2-1.8 (IDPS CDFCB layout, checked on real GCRSO files; satpy's
``viirs_sdr.yaml`` for the VIIRS names). Each field maps a Python name with its unit to a dataset of
``/All_Data/<collection>_All``:

* ``per``: what axis 0 counts: ``scan`` (CrIS arrays and VIIRS per-scan arrays) or ``row`` (VIIRS
  detector rows, ``rows_per_scan`` per scan).
* ``kind``: ``float`` (the IDPS float fills -999.9 ... -999.2 become NaN), ``scaled`` (uint16 with fills >= 65528,
  then ``value * scale + offset`` with one (scale, offset) pair per granule), ``time`` (int64 IET
  microseconds) or ``flags`` (unsigned integers kept as they are).
* ``to_si``: factor to the unit in the field's name (degrees -> radians, arcseconds -> radians).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

DEG = np.pi / 180.0
ARCSEC = np.pi / (180.0 * 3600.0)
FLOAT_FILLS = (-999.9, -999.8, -999.7, -999.6, -999.5, -999.4, -999.3, -999.2)  # IDPS float fills (NA ... SOUB)
UINT16_FILL_MIN = 65528  # IDPS uint16 fills are 65528 ... 65535


def is_float_fill(values) -> np.ndarray:
    """True where *values* hold one of the IDPS float fill codes (not merely a large negative number)."""
    v = np.asarray(values)
    return (v > -999.95) & (v < -999.15) & (np.abs(v * 10 - np.round(v * 10)) < 1e-2)


@dataclass(frozen=True)
class Field:
    dataset: str
    per: str = "scan"
    kind: str = "float"
    to_si: float = 1.0
    factors: str | None = None
    required: bool = True


@dataclass(frozen=True)
class Product:
    prefix: str
    collection: str
    kind: str
    rows_per_scan: int = 1
    scans_reserved: int | None = None  # VIIRS arrays always hold 48 scans per granule
    fields: dict = field(default_factory=dict)

    @property
    def data_group(self) -> str:
        return f"All_Data/{self.collection}_All"


CRIS_GEO_FIELDS = {
    "for_time_us": Field("FORTime", kind="time"),
    "start_time_us": Field("StartTime", kind="time"),
    "mid_time_us": Field("MidTime", kind="time"),
    "lat_rad": Field("Latitude", to_si=DEG),
    "lon_rad": Field("Longitude", to_si=DEG),
    "height_m": Field("Height"),
    "range_m": Field("SatelliteRange"),
    "zenith_rad": Field("SatelliteZenithAngle", to_si=DEG),
    "azimuth_rad": Field("SatelliteAzimuthAngle", to_si=DEG),
    "sc_position_m": Field("SCPosition"),
    "sc_velocity_m_s": Field("SCVelocity"),
    "sc_attitude_rad": Field("SCAttitude", to_si=ARCSEC),
}

CRIS_SDR_FIELDS = {
    "radiance_lw": Field("ES_RealLW"),  # mW/(m2 sr cm-1), unapodized
    "qf3": Field("QF3_CRISSDR", kind="flags"),
    "qf1_scan": Field("QF1_SCAN_CRISSDR", kind="flags", required=False),
}

VIIRS_SDR_FIELDS = {
    "bt_k": Field("BrightnessTemperature", per="row", kind="scaled", factors="BrightnessTemperatureFactors"),
    "qf1": Field("QF1_VIIRSIBANDSDR", per="row", kind="flags"),
}

VIIRS_GEO_FIELDS = {
    "lat_rad": Field("Latitude", per="row", to_si=DEG),
    "lon_rad": Field("Longitude", per="row", to_si=DEG),
    "start_time_us": Field("StartTime", kind="time"),
    "mid_time_us": Field("MidTime", kind="time"),
    "sc_position_m": Field("SCPosition"),
    "sc_velocity_m_s": Field("SCVelocity"),
    "sc_attitude_rad": Field("SCAttitude", to_si=ARCSEC),
}

# Terrain-corrected geolocation: Latitude/Longitude/Height is the 3-D point where the pixel's line of sight
# meets the terrain (formats.md 1.1 note); the ellipsoid product (GIMGO) puts its pixels at h = 0.
VIIRS_TC_GEO_FIELDS = {**VIIRS_GEO_FIELDS, "height_m": Field("Height", per="row")}

PRODUCTS = {p.prefix: p for p in (
    Product("SCRIS", "CrIS-SDR", "cris_sdr", fields=CRIS_SDR_FIELDS),
    Product("SCRIF", "CrIS-FS-SDR", "cris_sdr", fields=CRIS_SDR_FIELDS),
    Product("GCRSO", "CrIS-SDR-GEO", "cris_geo", fields=CRIS_GEO_FIELDS),
    Product("SVI05", "VIIRS-I5-SDR", "viirs_sdr", rows_per_scan=32, scans_reserved=48, fields=VIIRS_SDR_FIELDS),
    Product("GITCO", "VIIRS-IMG-GEO-TC", "viirs_geo", rows_per_scan=32, scans_reserved=48,
            fields=VIIRS_TC_GEO_FIELDS),
    Product("GIMGO", "VIIRS-IMG-GEO", "viirs_geo", rows_per_scan=32, scans_reserved=48, fields=VIIRS_GEO_FIELDS),
)}

# CrIS long-wave grid: 717 channels from 648.75 cm-1 every 0.625 cm-1 (2 guard channels each end), NSR and FSR.
CRIS_LW_FIRST_CM1 = 648.75
CRIS_LW_STEP_CM1 = 0.625
CRIS_LW_CHANNELS = 717


def cris_lw_wavenumbers_cm1(nchan: int = CRIS_LW_CHANNELS) -> np.ndarray:
    """Wavenumbers (cm-1) of the stored CrIS LW channels."""
    return CRIS_LW_FIRST_CM1 + CRIS_LW_STEP_CM1 * np.arange(nchan)
