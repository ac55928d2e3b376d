"""The datasets of the real products that the monitor never reads, so that a simulated file has the size
and the dataset list of a real one (``SimulationSpec.complete``): what reading in place saves is measured
on files like NODD's (benchmarks/nodd_ranges.py).

Names and shapes: docs/jpss-formats.md 1.4 (SCRIF), 1.5 (GCRSO, already complete), 1.7 (SVI05) and 1.8
(GITCO). Where the fact sheet names a dataset without its shape, the shape here is an assumption, marked
``# assumed`` (the CrIS engineering and quality datasets: a few kB in all; ``ES_NEdN*``: one spectrum per
FOV). The arrays are computed, not constant, where compression would otherwise make them vanish: the
GITCO view and solar angles and range from the pixels' geolocation, the CrIS imaginary spectra as noise.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.geometry import wgs84

F32_FILL = -999.3  # VDNE: where a pixel has no geolocation (bow-tie deleted)
SCAN_CHUNK = 6  # scans whose pixel angles are computed together (bounded memory)


def _enu(lat_rad: np.ndarray, lon_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """East, north and up unit vectors (ECEF) at geodetic (lat_rad, lon_rad)."""
    sl, cl, so, co = np.sin(lat_rad), np.cos(lat_rad), np.sin(lon_rad), np.cos(lon_rad)
    zero = np.zeros_like(lat_rad)
    return (
        np.stack([-so, co, zero], -1),
        np.stack([-sl * co, -sl * so, cl], -1),
        np.stack([cl * co, cl * so, sl], -1),
    )


def sun_direction_ecef(unix_s: ArrayLike) -> np.ndarray:
    """Unit vector (ECEF) toward the Sun at unix time(s) *unix_s*: declination from the day of the year,
    subsolar longitude from UTC (no equation of time; ~1 deg, enough for a dataset nobody reads here).

    Parameters
    ----------
    unix_s : array_like
        UTC seconds since 1970.

    Returns
    -------
    numpy.ndarray
        Unit vectors, ECEF.
    """
    t = np.asarray(unix_s, float)
    day = (t / 86400.0) % 365.2422
    decl = np.radians(-23.44) * np.cos(2 * np.pi * (day + 10.0) / 365.2422)
    lon = np.radians(180.0 - 360.0 * ((t / 86400.0) % 1.0))
    return np.stack([np.cos(decl) * np.cos(lon), np.cos(decl) * np.sin(lon), np.sin(decl)], -1)


def view_angles(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    h_m: ArrayLike,
    toward_ecef_m: np.ndarray,
    direction: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zenith and azimuth (deg, azimuth from north, -180..180) at each pixel toward a point (a position,
    m, ECEF; with *direction*, a unit direction), and the distance (m) to a position.

    Parameters
    ----------
    lat_rad, lon_rad : array_like
        Geodetic latitude and longitude, rad.
    h_m : array_like
        Height, m.
    toward_ecef_m : numpy.ndarray
        A position (m, ECEF), or with *direction* a unit direction.
    direction : bool, optional
        *toward_ecef_m* is a direction.

    Returns
    -------
    zenith_deg, azimuth_deg, range_m : numpy.ndarray
        Azimuth from north, -180..180.
    """
    p = wgs84.geodetic_to_ecef(lat_rad, lon_rad, h_m)
    d = toward_ecef_m if direction else toward_ecef_m - p
    dist = np.linalg.norm(d, axis=-1)
    e, n, u = _enu(lat_rad, lon_rad)
    zen = np.degrees(np.arccos(np.clip(np.sum(d * u, -1) / dist, -1.0, 1.0)))
    az = np.degrees(np.arctan2(np.sum(d * e, -1), np.sum(d * n, -1)))
    return zen, az, dist


def viirs_geo_extra(
    lat_deg: np.ndarray,
    lon_deg: np.ndarray,
    h_m: np.ndarray,
    sc_position_m: np.ndarray,
    scan_unix_s: np.ndarray,
    rows_per_scan: int,
) -> dict:
    """GITCO's pixel angles, range and per-scan solar angles and modes (1536 x 6400 float32 each).

    Parameters
    ----------
    lat_deg, lon_deg : numpy.ndarray
        The pixels' position, deg.
    h_m : numpy.ndarray
        Their height, m.
    sc_position_m : numpy.ndarray
        Each scan's spacecraft position, ECEF, m.
    scan_unix_s : numpy.ndarray
        Each scan's time, Unix s.
    rows_per_scan : int
        32.

    Returns
    -------
    dict
        Dataset name to array.
    """
    shape = lat_deg.shape
    out = {
        k: np.full(shape, F32_FILL, np.float32)
        for k in (
            "SatelliteZenithAngle",
            "SatelliteAzimuthAngle",
            "SatelliteRange",
            "SolarZenithAngle",
            "SolarAzimuthAngle",
        )
    }
    nscan = len(scan_unix_s)
    for s0 in range(0, nscan, SCAN_CHUNK):
        rows = slice(s0 * rows_per_scan, min(s0 + SCAN_CHUNK, nscan) * rows_per_scan)
        scan = np.arange(rows.start, rows.stop) // rows_per_scan
        lat, lon = np.radians(lat_deg[rows].astype(float)), np.radians(lon_deg[rows].astype(float))
        ok = lat_deg[rows] > -999.0
        sat = np.asarray(sc_position_m, float)[scan][:, None, :]
        zen, az, rng = view_angles(lat, lon, h_m[rows].astype(float), sat)
        s_zen, s_az, _ = view_angles(
            lat, lon, 0.0, sun_direction_ecef(np.asarray(scan_unix_s)[scan])[:, None, :], direction=True
        )
        for name, value in (
            ("SatelliteZenithAngle", zen),
            ("SatelliteAzimuthAngle", az),
            ("SatelliteRange", rng),
            ("SolarZenithAngle", s_zen),
            ("SolarAzimuthAngle", s_az),
        ):
            out[name][rows] = np.where(ok, value, F32_FILL)
    sub = np.asarray(sc_position_m, float)
    sub_lat = np.arcsin(sub[:, 2] / np.linalg.norm(sub, axis=-1))
    sub_lon = np.arctan2(sub[:, 1], sub[:, 0])
    sc_zen, sc_az, _ = view_angles(sub_lat, sub_lon, 0.0, sun_direction_ecef(scan_unix_s), direction=True)
    return out | {
        "SCSolarZenithAngle": sc_zen.astype(np.float32),
        "SCSolarAzimuthAngle": sc_az.astype(np.float32),
        "ModeGran": np.ones(1, np.uint8),
        "ModeScan": np.ones(nscan, np.uint8),
        "PadByte1": np.zeros(3, np.uint8),
    }


def viirs_sdr_extra(nscan: int, rows_per_scan: int) -> dict:
    """SVI05's per-scan and per-granule quality and packet counts.

    Parameters
    ----------
    nscan : int
        Scans.
    rows_per_scan : int
        32.

    Returns
    -------
    dict
        Dataset name to array.
    """
    return {
        "QF3_SCAN_RDR": np.zeros(nscan, np.uint8),
        "QF4_SCAN_SDR": np.zeros(nscan * rows_per_scan, np.uint8),
        "QF5_GRAN_BADDETECTOR": np.zeros(rows_per_scan, np.uint8),
        "ModeGran": np.ones(1, np.uint8),
        "ModeScan": np.ones(nscan, np.uint8),
        "NumberOfMissingPkts": np.zeros(nscan, np.int32),
        "NumberOfBadChecksums": np.zeros(nscan, np.int32),
        "NumberOfDiscardedPkts": np.zeros(nscan, np.int32),
        "PadByte1": np.zeros(3, np.uint8),
    }


def cris_sdr_extra(spectra: dict, rng: np.random.Generator) -> dict:
    """SCRIF's imaginary spectra (noise, the shape of the real ones), NEdN and engineering datasets;
    *spectra* maps band (LW, MW, SW) to its ES_Real array (nscan, 30, 9, nchan).

    Parameters
    ----------
    spectra : dict
        Band (LW, MW, SW) to its ES_Real array (nscan, 30, 9, nchan).
    rng : numpy.random.Generator
        The noise's generator.

    Returns
    -------
    dict
        Dataset name to array.
    """
    out: dict = {}
    nscan = next(iter(spectra.values())).shape[0]
    for band, real in spectra.items():
        out[f"ES_Imaginary{band}"] = rng.normal(0.0, 0.05, real.shape).astype(np.float32)
        out[f"ES_NEdN{band}"] = np.full((9, real.shape[-1]), 0.1, np.float32)  # assumed
    per_fov_band = (nscan, 30, 9, 3)  # assumed, as QF3_CRISSDR
    for name in ("ES_ZPDAmplitude", "ES_ZPDFringeCount", "ES_RDRImpulseNoise", "SDRFringeCount"):
        out[name] = np.zeros(per_fov_band, np.int32)
    for name in ("DS_SpectralStability", "DS_Symmetry", "DS_WindowSize"):
        out[name] = np.zeros((nscan, 2, 9, 3), np.uint8)  # assumed: per sweep direction, FOV, band
    for name in (
        "ICT_SpectralStability",
        "ICT_TemperatureConsistency",
        "ICT_TemperatureStability",
        "ICT_WindowSize",
    ):
        out[name] = np.zeros((nscan, 2, 9, 3), np.uint8)  # assumed
    for name in ("MeasuredLaserWavelength", "MonitoredLaserWavelength", "ResamplingLaserWavelength"):
        out[name] = np.full(nscan, 773.13e-9, np.float64)  # assumed: one per scan (m)
    out["NumberOfValidPRTTemps"] = np.full((nscan, 2), 2, np.int32)  # assumed
    out["QF2_CRISSDR"] = np.zeros((nscan, 9, 3), np.uint8)
    out["QF4_CRISSDR"] = np.zeros(per_fov_band, np.uint8)  # assumed, as QF3
    return out
