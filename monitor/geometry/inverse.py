"""Inverse geolocation: from CrIS GEO fields to the line of sight in the spacecraft body frame.

Wang et al. 2017, section 2.2, steps 1-6 (with the ECI detour replaced by the inertial-velocity OCS of
:mod:`monitor.geometry.frames`), and the forward path back to the ground used by the perturbation.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike

from monitor.geometry import frames, orbit, wgs84


@dataclass(frozen=True)
class FovGeometry:
    """Viewing geometry of every FOV; leading shape (nscan, nfor, nfov) for a CrIS granule.

    ground_ecef_m: FOV centre on the ellipsoid (h = 0, as IDPS writes it), metres.
    sat_ecef_m: satellite position implied by the FOV (ground point + range toward the satellite), metres.
    los_ecef: unit line of sight satellite -> ground, ECEF.
    velocity_ecef_m_s: spacecraft ECEF velocity at the FOR time.
    sbf_to_ecef: rotation (..., 3, 3) taking an SBF vector to ECEF.
    los_sbf: unit line of sight in the SBF.
    alpha_rad, beta_rad: in-track and cross-track LOS angles, equations (1)-(2).
    """

    ground_ecef_m: np.ndarray
    sat_ecef_m: np.ndarray
    los_ecef: np.ndarray
    velocity_ecef_m_s: np.ndarray
    sbf_to_ecef: np.ndarray
    los_sbf: np.ndarray
    alpha_rad: np.ndarray
    beta_rad: np.ndarray


def satellite_from_fov(
    lat_rad: ArrayLike, lon_rad: ArrayLike, zenith_rad: ArrayLike, azimuth_rad: ArrayLike, range_m: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """The ground point (h = 0) and the satellite position a FOV's geometry implies.

    Steps 1-2 of section 2.2: the ENU unit vector toward the satellite from zenith and azimuth, rotated to
    ECEF at the FOV's latitude and longitude, scaled by the satellite range.

    Parameters
    ----------
    lat_rad, lon_rad : array_like
        Geodetic latitude and longitude of each FOV's ground point, rad.
    zenith_rad, azimuth_rad : array_like
        The satellite's zenith and azimuth seen from the ground point, rad.
    range_m : array_like
        The range from the ground point to the satellite, m.

    Returns
    -------
    ground_ecef_m, sat_ecef_m : numpy.ndarray
        ECEF positions, m, shape (..., 3).
    """
    ground = wgs84.geodetic_to_ecef(lat_rad, lon_rad, 0.0)
    look = wgs84.look_vector_ecef(lat_rad, lon_rad, zenith_rad, azimuth_rad)
    return ground, ground + np.asarray(range_m, float)[..., None] * look


def inverse_geolocation(
    lat_rad: np.ndarray,
    lon_rad: np.ndarray,
    zenith_rad: np.ndarray,
    azimuth_rad: np.ndarray,
    range_m: np.ndarray,
    for_time_us: np.ndarray,
    mid_time_us: np.ndarray,
    sc_position_m: np.ndarray,
    sc_velocity_m_s: np.ndarray,
    sc_attitude_rad: np.ndarray,
) -> FovGeometry:
    """The line of sight of each FOV in the spacecraft body frame from the GEO fields (section 2.2).

    The per-scan ephemeris is propagated (position, velocity) or interpolated (attitude) to each FOR's time.

    Parameters
    ----------
    lat_rad, lon_rad : array_like
        Geodetic latitude and longitude of each FOV's ground point, rad.
    zenith_rad, azimuth_rad : array_like
        The satellite's zenith and azimuth seen from the ground point, rad.
    range_m : array_like
        The range from the ground point to the satellite, m.
        All of shape (nscan, nfor, nfov).
    for_time_us : numpy.ndarray
        Each FOR's time, IET us, shape (nscan, nfor).
    mid_time_us : numpy.ndarray
        Each scan's middle time, IET us, shape (nscan,).
    sc_position_m, sc_velocity_m_s : numpy.ndarray
        The spacecraft's ECEF position (m) and velocity (m/s) at each scan's middle, shape (nscan, 3).
    sc_attitude_rad : numpy.ndarray
        Roll, pitch and yaw at each scan's middle, rad, shape (nscan, 3).

    Returns
    -------
    FovGeometry
        Ground points, satellite positions, the LOS in ECEF and in the spacecraft body frame, the rotation
        between them, and each FOV's alpha (in-track) and beta (cross-track), rad.
    """
    ground, sat = satellite_from_fov(lat_rad, lon_rad, zenith_rad, azimuth_rad, range_m)
    los_ecef = frames.unit(ground - sat)
    _, vel = orbit.state_at(for_time_us, mid_time_us, sc_position_m, sc_velocity_m_s)
    att = orbit.interpolate_per_scan(for_time_us, mid_time_us, sc_attitude_rad)
    nfov = ground.shape[-2]
    vel = np.repeat(vel[..., None, :], nfov, axis=-2)
    att = np.repeat(att[..., None, :], nfov, axis=-2)
    to_ecef = frames.sbf_to_ecef(sat, vel, att)
    los_sbf = np.einsum("...ji,...j->...i", to_ecef, los_ecef)
    alpha, beta = frames.los_angles(los_sbf)
    return FovGeometry(ground, sat, los_ecef, vel, to_ecef, los_sbf, alpha, beta)


def forward_geolocation(
    sat_ecef_m: np.ndarray, sbf_to_ecef: np.ndarray, los_sbf: np.ndarray, h_m: ArrayLike = 0.0
) -> np.ndarray:
    """The ground point where a line of sight in the spacecraft body frame meets the ellipsoid.

    The SBF -> OCS -> ECEF path of section 2.4.

    Parameters
    ----------
    sat_ecef_m : numpy.ndarray
        Spacecraft position, ECEF, m, shape (..., 3).
    sbf_to_ecef : numpy.ndarray
        Rotation from the spacecraft body frame to ECEF, shape (..., 3, 3).
    los_sbf : numpy.ndarray
        Lines of sight in the spacecraft body frame, shape (..., 3).
    h_m : array_like, optional
        Height above the ellipsoid of the surface met, m.

    Returns
    -------
    numpy.ndarray
        ECEF points, m, shape (..., 3); NaN where the LOS misses the Earth.
    """
    los_ecef = np.einsum("...ij,...j->...i", sbf_to_ecef, los_sbf)
    t = wgs84.intersect_ellipsoid(sat_ecef_m, los_ecef, h_m)
    return np.asarray(sat_ecef_m) + t[..., None] * los_ecef


class CrisGeoFields(Protocol):
    """What :func:`granule_geometry` reads of a CrIS GEO granule (:class:`monitor.sdr.CrisGeoGranule`,
    a floor above): per FOV (scan, FOR, FOV) unless said."""

    @property  # numpydoc ignore=RT01
    def valid(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def lat_rad(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def lon_rad(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def zenith_rad(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def azimuth_rad(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def range_m(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def for_time_us(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def mid_time_us(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def sc_position_m(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def sc_velocity_m_s(self) -> np.ndarray: ...
    @property  # numpydoc ignore=RT01
    def sc_attitude_rad(self) -> np.ndarray: ...


def granule_geometry(geo: CrisGeoFields) -> FovGeometry:
    """The inverse geolocation of a CrIS GEO granule (:class:`monitor.sdr.CrisGeoGranule`).

    Fill FOVs are given harmless values (a ground point at 0, 0 and a range of 1000 km) so that the arrays
    stay finite.

    Parameters
    ----------
    geo : CrisGeoFields
        The granule's GEO fields.

    Returns
    -------
    FovGeometry
        As :func:`inverse_geolocation`; mask it with ``geo.valid``.
    """
    valid = geo.valid
    return inverse_geolocation(
        np.where(valid, geo.lat_rad, 0.0),
        np.where(valid, geo.lon_rad, 0.0),
        np.where(valid, geo.zenith_rad, 0.0),
        np.where(valid, geo.azimuth_rad, 0.0),
        np.where(valid, geo.range_m, 1e6),
        geo.for_time_us,
        geo.mid_time_us,
        np.nan_to_num(geo.sc_position_m),
        np.nan_to_num(geo.sc_velocity_m_s),
        np.nan_to_num(geo.sc_attitude_rad),
    )
