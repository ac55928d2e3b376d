"""Forward geolocation of CrIS FOVs: spacecraft-frame lines of sight to the ground (section 2.4).

The spacecraft-level half of the geolocation, shared by every JPSS instrument: the ephemeris given
at each scan's MidTime is propagated to each FOR time (two-body + J2), the attitude interpolated,
the LOS taken through the OCS to ECEF and intersected with the WGS84 ellipsoid. IDPS writes GCRSO
latitude/longitude on the plain ellipsoid (h = 0, docs/jpss-formats.md 2.3, point 8), so h_m defaults to 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monitor.geometry import frames, orbit, wgs84
from monitor.geometry.inverse import forward_geolocation


@dataclass(frozen=True)
class GroundView:
    """Geolocation fields of every FOV, shaped (nscan, 30, 9); NaN where the LOS misses or data are missing.

    lat_rad, lon_rad: geodetic position of the FOV centre; zenith_rad, azimuth_rad: satellite zenith
    and azimuth (clockwise from north) seen from it; range_m: distance to the satellite; ground_ecef_m:
    the point itself (..., 3).
    """

    lat_rad: np.ndarray
    lon_rad: np.ndarray
    zenith_rad: np.ndarray
    azimuth_rad: np.ndarray
    range_m: np.ndarray
    ground_ecef_m: np.ndarray


def geolocate_fovs(
    los_spacecraft: np.ndarray,
    for_time_us: np.ndarray,
    mid_time_us: np.ndarray,
    sc_position_m: np.ndarray,
    sc_velocity_m_s: np.ndarray,
    sc_attitude_rad: np.ndarray,
    h_m: float | np.ndarray = 0.0,
) -> GroundView:
    """Geolocate the line of sight of every FOV of every scan (the forward path of section 2.4).

    Parameters
    ----------
    los_spacecraft : numpy.ndarray
        Each FOR's and FOV's LOS in the spacecraft body frame, shape (30, 9, 3).
    for_time_us : numpy.ndarray
        Each FOR's time, IET us, shape (nscan, 30); times <= 0 (fill) give NaN.
    mid_time_us : numpy.ndarray
        Each scan's middle time, IET us, shape (nscan,).
    sc_position_m, sc_velocity_m_s : numpy.ndarray
        The spacecraft's ECEF position (m) and velocity (m/s) at each scan's middle, shape (nscan, 3).
    sc_attitude_rad : numpy.ndarray
        Roll, pitch and yaw at each scan's middle, rad, shape (nscan, 3).
    h_m : float or numpy.ndarray, optional
        Height of the surface met above the ellipsoid, m (GCRSO: 0).

    Returns
    -------
    GroundView
        Latitude and longitude (rad), the satellite's zenith and azimuth (rad), range (m) and the ground
        points (ECEF, m) of every FOV, shape (nscan, 30, 9).
    """
    t = np.asarray(for_time_us, np.int64)
    bad_time = t <= 0
    t = np.where(bad_time, np.asarray(mid_time_us, np.int64)[:, None], t)
    r, v = orbit.state_at(t, mid_time_us, sc_position_m, sc_velocity_m_s)
    att = orbit.interpolate_per_scan(t, mid_time_us, sc_attitude_rad)
    to_ecef = frames.sbf_to_ecef(r, v, att)  # (nscan, 30, 3, 3)
    los = np.broadcast_to(np.asarray(los_spacecraft, float), t.shape[:1] + np.shape(los_spacecraft))
    sat = np.broadcast_to(r[:, :, None, :], los.shape)
    ground = forward_geolocation(sat, to_ecef[:, :, None], los, h_m)
    ground[np.broadcast_to(bad_time[:, :, None, None], ground.shape)] = np.nan
    lat, lon, _ = wgs84.ecef_to_geodetic(ground)
    zen, az, rng = wgs84.zenith_azimuth(ground, sat)
    return GroundView(lat, lon, zen, az, rng, ground)
