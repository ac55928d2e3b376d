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
    """Ground point (h = 0) and satellite position implied by a FOV's geometry, both ECEF metres.

    Steps 1-2 of section 2.2: the ENU unit vector toward the satellite from zenith/azimuth, rotated to
    ECEF at the FOV's latitude/longitude, scaled by the satellite range.
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
    """LOS of each FOV in the SBF from the GEO fields (section 2.2).

    FOV fields are (nscan, nfor, nfov); *for_time_us* (nscan, nfor) IET; the per-scan ephemeris
    (*mid_time_us* (nscan,), *sc_position_m*, *sc_velocity_m_s*, *sc_attitude_rad* (nscan, 3) roll,
    pitch, yaw) is propagated (position, velocity) or interpolated (attitude) to each FOR time.
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
    """Ground point (ECEF metres) where an SBF line of sight from *sat_ecef_m* meets the ellipsoid.

    The SBF -> OCS -> ECEF path of section 2.4; NaN where the LOS misses the Earth.
    """
    los_ecef = np.einsum("...ij,...j->...i", sbf_to_ecef, los_sbf)
    t = wgs84.intersect_ellipsoid(sat_ecef_m, los_ecef, h_m)
    return np.asarray(sat_ecef_m) + t[..., None] * los_ecef


class CrisGeoFields(Protocol):
    """What :func:`granule_geometry` reads of a CrIS GEO granule (:class:`monitor.sdr.CrisGeoGranule`,
    a floor above): per FOV (scan, FOR, FOV) unless said."""

    @property
    def valid(self) -> np.ndarray: ...
    @property
    def lat_rad(self) -> np.ndarray: ...
    @property
    def lon_rad(self) -> np.ndarray: ...
    @property
    def zenith_rad(self) -> np.ndarray: ...
    @property
    def azimuth_rad(self) -> np.ndarray: ...
    @property
    def range_m(self) -> np.ndarray: ...
    @property
    def for_time_us(self) -> np.ndarray: ...
    @property
    def mid_time_us(self) -> np.ndarray: ...
    @property
    def sc_position_m(self) -> np.ndarray: ...
    @property
    def sc_velocity_m_s(self) -> np.ndarray: ...
    @property
    def sc_attitude_rad(self) -> np.ndarray: ...


def granule_geometry(geo: CrisGeoFields) -> FovGeometry:
    """The inverse geolocation of a CrIS GEO granule (:class:`monitor.sdr.CrisGeoGranule`): its fields in,
    fill FOVs given harmless values (a ground point at 0, 0 and a range of 1000 km) so that the arrays stay
    finite; mask the result with ``geo.valid``."""
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
