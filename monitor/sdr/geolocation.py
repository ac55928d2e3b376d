"""The geolocation a genuine granule obeys: its ephemeris, its lines of sight, its pixels on the ground.

The orbit radius and speed of the named satellite, an attitude small, smooth and measured (it changes from
scan to scan); a CrIS FOV's ground point plus its range along zenith and azimuth closing on the spacecraft
(Wang et al. 2017, section 2.2, run backwards); a VIIRS scan's middle pixel below the spacecraft;
neighbouring VIIRS pixels close on the ground. A corrupt granule fails one of them with
``FILE: FIELD: REASON`` (:func:`monitor.sdr.consistency.check_relations` runs them).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from monitor.core.satellites import SATELLITES
from monitor.geometry import orbit, wgs84
from monitor.geometry.inverse import satellite_from_fov
from monitor.sdr.granule_error import GranuleError
from monitor.sdr.granules import CrisGeoGranule, GeoGranule, GranuleRef, ViirsGeoGranule
from monitor.sdr.products import Product

RADIUS_TOLERANCE_M = 30e3
SPEED_LIMITS_M_S = (7.3e3, 7.7e3)
ATTITUDE_LIMIT_ARCSEC = 300.0
ATTITUDE_STEP_ARCSEC = 30.0
ARCSEC_RAD = np.pi / (180.0 * 3600.0)
LOS_CLOSURE_M = 200.0
NADIR_TOLERANCE_M = 20e3
PIXEL_STEP_KM = 5.0  # I-band pixels along a row lie 0.375-0.8 km apart; a corrupt value leaps far further


def check_ephemeris(path: GranuleRef, product: Product, granule: GeoGranule, has_data: np.ndarray) -> None:
    """Orbit radius and speed of the named satellite; attitude small, smooth and measured.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    has_data : numpy.ndarray
        Per scan, whether it holds data.
    """
    sat = SATELLITES[granule.meta.platform]
    g = product.data_group
    radius_m = wgs84.A_M + sat.altitude_m  # the mean altitude is above the equatorial radius
    r = np.linalg.norm(granule.sc_position_m[has_data], axis=-1)
    r = r[np.isfinite(r)]
    if r.size and np.abs(r - radius_m).max() > RADIUS_TOLERANCE_M:
        bad = r[np.argmax(np.abs(r - radius_m))]
        raise GranuleError(
            path,
            f"{g}/SCPosition",
            f"orbit radius {bad / 1e3:.1f} km, {sat.name} flies at {radius_m / 1e3:.0f} km",
        )
    v = np.linalg.norm(granule.sc_velocity_m_s[has_data], axis=-1)
    v = v[np.isfinite(v)]
    if v.size and (v.min() < SPEED_LIMITS_M_S[0] or v.max() > SPEED_LIMITS_M_S[1]):
        bad = v.min() if v.min() < SPEED_LIMITS_M_S[0] else v.max()
        raise GranuleError(
            path,
            f"{g}/SCVelocity",
            f"speed {bad:.0f} m/s, not the {SPEED_LIMITS_M_S[0]:.0f}..{SPEED_LIMITS_M_S[1]:.0f} m/s of "
            f"{sat.name}",
        )
    # the velocity points where the spacecraft goes: from one scan's position towards the next's
    pos, vel = granule.sc_position_m[has_data], granule.sc_velocity_m_s[has_data]
    ahead = np.sum(0.5 * (vel[1:] + vel[:-1]) * np.diff(pos, axis=0), axis=-1)
    ahead = ahead[np.isfinite(ahead)]
    if ahead.size and np.any(ahead <= 0):
        raise GranuleError(
            path, f"{g}/SCVelocity", "the velocity points away from the next scan's position (a sign lost)"
        )
    att = granule.sc_attitude_rad[has_data] / ARCSEC_RAD
    att = att[np.isfinite(att).all(axis=-1)]
    name = f"{g}/SCAttitude"
    if att.size:
        if np.abs(att).max() > ATTITUDE_LIMIT_ARCSEC:
            raise GranuleError(
                path,
                name,
                f"{np.abs(att).max():.4g} arcsec, more than the {ATTITUDE_LIMIT_ARCSEC:g} of normal "
                "operations",
            )
        if len(att) > 1 and np.abs(np.diff(att, axis=0)).max() > ATTITUDE_STEP_ARCSEC:
            raise GranuleError(
                path,
                name,
                f"jumps {np.abs(np.diff(att, axis=0)).max():.4g} arcsec from one scan to the next (at most "
                f"{ATTITUDE_STEP_ARCSEC:g})",
            )
        if not att.any():
            raise GranuleError(path, name, "exactly zero in every scan: not a measured attitude")
        # a measured attitude jitters (tenths of an arcsec) from scan to scan: identical values are a copy
        if len(att) > 2 and (att == att[0]).all():
            raise GranuleError(
                path,
                name,
                f"the same {att[0].tolist()} arcsec in all {len(att)} scans: not a measured attitude",
            )


def check_line_of_sight(path: GranuleRef, product: Product, granule: CrisGeoGranule) -> None:
    """CrIS GEO: ground point + range along zenith/azimuth = the spacecraft at the FOR time.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    """
    valid = granule.valid
    if not valid.any():
        return
    lat, lon, zen, az, rng = (
        np.where(valid, getattr(granule, k), v)
        for k, v in (
            ("lat_rad", 0.0),
            ("lon_rad", 0.0),
            ("zenith_rad", 0.0),
            ("azimuth_rad", 0.0),
            ("range_m", 1e6),
        )
    )
    _, implied = satellite_from_fov(lat, lon, zen, az, rng)
    scans = np.isfinite(granule.sc_position_m).all(axis=-1) & (granule.mid_time_us > 0)
    if not scans.any():
        return
    r, _ = orbit.state_at(
        granule.for_time_us,
        granule.mid_time_us[scans],
        granule.sc_position_m[scans],
        np.nan_to_num(granule.sc_velocity_m_s[scans]),
    )
    miss = np.where(valid, np.linalg.norm(implied - r[..., None, :], axis=-1), 0.0)
    if miss.max() > LOS_CLOSURE_M:
        s, f, v = np.unravel_index(np.argmax(miss), miss.shape)
        raise GranuleError(
            path,
            f"{product.data_group}/Latitude, Longitude, SatelliteRange, SatelliteZenith/AzimuthAngle",
            f"scan {s + 1} FOR {f + 1} FOV {v + 1}: the ground point plus the range along the view "
            f"direction misses the spacecraft (SCPosition at FORTime) by {miss.max() / 1e3:.3g} km (at most "
            f"{LOS_CLOSURE_M:g} m)",
        )


def check_nadir(path: GranuleRef, product: Product, granule: ViirsGeoGranule, has_data: np.ndarray) -> None:
    """VIIRS GEO: the middle pixel of each scan lies below the spacecraft at the scan's MidTime.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    has_data : numpy.ndarray
        Per scan, whether it holds data.
    """
    rows = product.rows_per_scan
    centre = granule.lat_rad.shape[1] // 2
    scans = np.flatnonzero(has_data & np.isfinite(granule.sc_position_m).all(axis=-1))
    if not scans.size:
        return
    row = scans * rows + rows // 2
    lat, lon = granule.lat_rad[row, centre], granule.lon_rad[row, centre]
    h = granule.height_m[row, centre] if granule.height_m is not None else np.zeros(len(row))
    ok = np.isfinite(lat) & np.isfinite(lon)
    if not ok.any():
        return
    pixel = wgs84.geodetic_to_ecef(lat[ok], lon[ok], np.nan_to_num(h[ok]))
    sat = granule.sc_position_m[scans[ok]]
    _, _, sat_h = wgs84.ecef_to_geodetic(sat)
    off = np.abs(np.linalg.norm(sat - pixel, axis=-1) - (sat_h - np.nan_to_num(h[ok])))
    if off.max() > NADIR_TOLERANCE_M:
        i = int(np.argmax(off))
        raise GranuleError(
            path,
            f"{product.data_group}/Latitude, Longitude, SCPosition",
            f"scan {scans[ok][i] + 1}: the middle pixel is not below the spacecraft "
            f"({off[i] / 1e3:.0f} km off)",
        )


@numba.njit(cache=True, nogil=True)
def _first_leap(lat_rad: np.ndarray, lon_rad: np.ndarray, limit_rad: float) -> tuple[int, int, float]:
    """(row, column, step_rad) of the first pair of neighbours in a row farther apart than *limit_rad*
    on the sphere, (-1, -1, 0) if none. The step is hypot(d_lat, d_lon cos(lat)), d_lon across the
    antimeridian; the cosine only where d_lon alone could exceed the limit (near a pole)."""
    two_pi = 2.0 * np.pi
    for r in range(lat_rad.shape[0]):
        for c in range(lat_rad.shape[1] - 1):
            d_lat = abs(lat_rad[r, c + 1] - lat_rad[r, c])  # NaN (fill) fails every comparison
            d_lon = abs(lon_rad[r, c + 1] - lon_rad[r, c])
            d_lon = min(d_lon, two_pi - d_lon)
            if d_lat > limit_rad or d_lon > limit_rad:
                step = math.hypot(d_lat, d_lon * math.cos(lat_rad[r, c + 1]))
                if step > limit_rad:
                    return r, c, step
    return -1, -1, 0.0


def check_pixel_steps(path: GranuleRef, product: Product, granule: GeoGranule) -> None:
    """VIIRS GEO: neighbouring pixels of a row lie within PIXEL_STEP_KM of each other on the ground.

    A corrupt latitude or longitude (a flipped byte of a float) moves its pixel hundreds of km or more; no
    other check sees one pixel among ten million. Pairs with a fill (unread scans included) are skipped.

    Parameters
    ----------
    path : GranuleRef
        The file, named in an error.
    product : Product
        Its product's table.
    granule : Granule
        The granule read.
    """
    r, c, step = _first_leap(granule.lat_rad, granule.lon_rad, PIXEL_STEP_KM / (wgs84.A_M / 1e3))
    if r >= 0:
        raise GranuleError(
            path,
            f"{product.data_group}/Latitude, Longitude",
            f"row {r}, columns {c}-{c + 1}: neighbouring pixels {step * wgs84.A_M / 1e3:.0f} km apart "
            f"(more than {PIXEL_STEP_KM:g} km)",
        )
