"""Offset angles expressed as distances on the ground, along and across the ground track."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.geometry import frames, wgs84
from monitor.geometry.inverse import forward_geolocation


def track_axes(ground_ecef_m: np.ndarray, velocity_ecef_m_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit horizontal vectors along and across the ground track at ground points.

    Along-track is the spacecraft's ECEF velocity projected on the local horizontal; cross-track is along x
    up, to the right of the flight direction.

    Parameters
    ----------
    ground_ecef_m : numpy.ndarray
        Ground points, ECEF, m, shape (..., 3).
    velocity_ecef_m_s : numpy.ndarray
        Spacecraft velocity, ECEF, m/s, shape (..., 3).

    Returns
    -------
    along, cross : numpy.ndarray
        Unit vectors in ECEF, shape (..., 3).
    """
    up = wgs84.geodetic_up(ground_ecef_m)
    v = np.asarray(velocity_ecef_m_s, float)
    along = frames.unit(v - np.sum(v * up, axis=-1, keepdims=True) * up)
    cross = np.cross(along, up)
    return along, cross


def offset_km(
    sat_ecef_m: np.ndarray,
    sbf_to_ecef: np.ndarray,
    alpha_rad: ArrayLike,
    beta_rad: ArrayLike,
    velocity_ecef_m_s: np.ndarray,
    d_alpha_rad: ArrayLike,
    d_beta_rad: ArrayLike,
) -> tuple[np.ndarray, np.ndarray]:
    """The ground displacement of turning a LOS by (d_alpha, d_beta) in the spacecraft body frame.

    Both the original and the turned LOS are intersected with the WGS84 ellipsoid; the difference is projected
    on the local along-track and cross-track directions at the original point (:func:`track_axes`).

    Parameters
    ----------
    sat_ecef_m : numpy.ndarray
        Spacecraft position, ECEF, m, shape (..., 3).
    sbf_to_ecef : numpy.ndarray
        Rotation from the spacecraft body frame to ECEF, shape (..., 3, 3).
    alpha_rad, beta_rad : array_like
        The LOS's in-track and cross-track angles in the spacecraft body frame, rad.
    velocity_ecef_m_s : numpy.ndarray
        Spacecraft velocity, ECEF, m/s, shape (..., 3).
    d_alpha_rad, d_beta_rad : array_like
        The turn, rad.

    Returns
    -------
    in_track_km, cross_track_km : numpy.ndarray
        The displacement along the flight direction and to its right, km.
    """
    p0 = forward_geolocation(sat_ecef_m, sbf_to_ecef, frames.los_from_angles(alpha_rad, beta_rad))
    p1 = forward_geolocation(
        sat_ecef_m,
        sbf_to_ecef,
        frames.los_from_angles(np.asarray(alpha_rad) + d_alpha_rad, np.asarray(beta_rad) + d_beta_rad),
    )
    along, cross = track_axes(p0, velocity_ecef_m_s)
    d = p1 - p0
    return np.sum(d * along, axis=-1) / 1e3, np.sum(d * cross, axis=-1) / 1e3
