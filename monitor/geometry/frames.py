"""Rotations, the orbital coordinate system (OCS) and the spacecraft body frame (SBF).

Frames (Wang et al. 2017, table 1 and section 2.2):

* ECEF: Earth-centred Earth-fixed, metres.
* OCS: origin at the spacecraft; z toward geodetic nadir, y = unit(z x v_inertial), x = y x z
  (x is roughly the flight direction, y points to the right of the ground track).
* SBF: the OCS turned by the spacecraft attitude (roll about x, pitch about y, yaw about z) in the
  yaw-roll-pitch (3-1-2) order.

The paper goes OCS <- ECI <- ECEF with NOVAS. Because one ECEF->ECI rotation applied to both the LOS
and the OCS axes leaves every dot product unchanged, the OCS axes are built here directly in ECEF with
the *inertial* velocity expressed in ECEF, v_ecef + omega x r (docs/science.md; ``tests/geometry`` checks
the equivalence against an explicit ECI computation).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.geometry.wgs84 import OMEGA_EARTH_RAD_S, geodetic_up

ARCSEC_RAD = np.pi / (180.0 * 3600.0)


def rot_x(psi_rad: ArrayLike) -> np.ndarray:
    """R_x(psi), equation (11): the active rotation about x.

    Parameters
    ----------
    psi_rad : array_like
        The angle, rad.

    Returns
    -------
    numpy.ndarray
        The rotation matrices, shape ``psi_rad.shape + (3, 3)``.
    """
    c, s = np.cos(psi_rad), np.sin(psi_rad)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rot_y(theta_rad: ArrayLike) -> np.ndarray:
    """P_y(theta), equation (12): the active rotation about y.

    Parameters
    ----------
    theta_rad : array_like
        The angle, rad.

    Returns
    -------
    numpy.ndarray
        The rotation matrices, shape ``theta_rad.shape + (3, 3)``.
    """
    c, s = np.cos(theta_rad), np.sin(theta_rad)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_z(phi_rad: ArrayLike) -> np.ndarray:
    """Y_z(phi), equation (13): the active rotation about z.

    Parameters
    ----------
    phi_rad : array_like
        The angle, rad.

    Returns
    -------
    numpy.ndarray
        The rotation matrices, shape ``phi_rad.shape + (3, 3)``.
    """
    c, s = np.cos(phi_rad), np.sin(phi_rad)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def unit(v: ArrayLike) -> np.ndarray:
    """*v* divided by its norm along the last axis.

    Parameters
    ----------
    v : array_like
        Vectors, shape (..., 3), in any frame and unit.

    Returns
    -------
    numpy.ndarray
        Unit vectors in the same frame, shape of *v*.
    """
    v = np.asarray(v, float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def inertial_velocity_ecef(r_ecef_m: ArrayLike, v_ecef_m_s: ArrayLike) -> np.ndarray:
    """The inertial velocity expressed in ECEF axes, v_ecef + omega_earth x r.

    Parameters
    ----------
    r_ecef_m : array_like
        Spacecraft position, ECEF, m, shape (..., 3).
    v_ecef_m_s : array_like
        Spacecraft velocity relative to the rotating Earth, ECEF, m/s, shape (..., 3).

    Returns
    -------
    numpy.ndarray
        The inertial velocity in ECEF axes, m/s, shape (..., 3).
    """
    r = np.asarray(r_ecef_m, float)
    omega = np.array([0.0, 0.0, OMEGA_EARTH_RAD_S])
    return np.asarray(v_ecef_m_s, float) + np.cross(omega, r)


def ocs_axes_ecef(r_ecef_m: ArrayLike, v_ecef_m_s: ArrayLike) -> np.ndarray:
    """The orbital coordinate system's axes as the columns of a matrix in ECEF (section 2.2.2).

    z = geodetic nadir at the spacecraft, y = unit(z x v_inertial), x = y x z.

    Parameters
    ----------
    r_ecef_m : array_like
        Spacecraft position, ECEF, m, shape (..., 3).
    v_ecef_m_s : array_like
        Spacecraft velocity relative to the rotating Earth, ECEF, m/s, shape (..., 3).

    Returns
    -------
    numpy.ndarray
        Shape (..., 3, 3): maps an OCS vector to ECEF.
    """
    z = -geodetic_up(r_ecef_m)
    y = unit(np.cross(z, inertial_velocity_ecef(r_ecef_m, v_ecef_m_s)))
    x = np.cross(y, z)
    return np.stack([x, y, z], axis=-1)


def sbf_to_ocs(roll_rad: ArrayLike, pitch_rad: ArrayLike, yaw_rad: ArrayLike) -> np.ndarray:
    """The rotation taking a spacecraft-body-frame vector to the OCS for the given attitude.

    Yaw-roll-pitch (3-1-2): the orbit-to-body matrix is A = P(-pitch) R(-roll) Y(-yaw), so body to orbit is
    A^T = Y(yaw) R(roll) P(pitch), the convention that reproduces IDPS GCRSO (docs/jpss-formats.md 2.3).

    Parameters
    ----------
    roll_rad, pitch_rad, yaw_rad : array_like
        The attitude angles, rad, broadcast together.

    Returns
    -------
    numpy.ndarray
        The rotations, shape (..., 3, 3).
    """
    return rot_z(yaw_rad) @ rot_x(roll_rad) @ rot_y(pitch_rad)


def sbf_to_ecef(r_ecef_m: ArrayLike, v_ecef_m_s: ArrayLike, attitude_rad: ArrayLike) -> np.ndarray:
    """The rotation taking a spacecraft-body-frame vector to ECEF.

    Parameters
    ----------
    r_ecef_m : array_like
        Spacecraft position, ECEF, m, shape (..., 3).
    v_ecef_m_s : array_like
        Spacecraft velocity relative to the rotating Earth, ECEF, m/s, shape (..., 3).
    attitude_rad : array_like
        Roll, pitch and yaw, rad, shape (..., 3).

    Returns
    -------
    numpy.ndarray
        The rotations, shape (..., 3, 3).
    """
    att = np.asarray(attitude_rad, float)
    return ocs_axes_ecef(r_ecef_m, v_ecef_m_s) @ sbf_to_ocs(att[..., 0], att[..., 1], att[..., 2])


def los_angles(los_sbf: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """In-track alpha = atan(x/z) and cross-track beta = atan(y/z) of SBF vectors, equations (1)-(2).

    Parameters
    ----------
    los_sbf : array_like
        Lines of sight in the spacecraft body frame, shape (..., 3).

    Returns
    -------
    alpha_rad, beta_rad : numpy.ndarray
        The in-track and cross-track angles, rad, shape (...).
    """
    los = np.asarray(los_sbf, float)
    return np.arctan2(los[..., 0], los[..., 2]), np.arctan2(los[..., 1], los[..., 2])


def los_from_angles(alpha_rad: ArrayLike, beta_rad: ArrayLike) -> np.ndarray:
    """The SBF unit vector with in-track angle alpha and cross-track angle beta (z > 0).

    unit(tan alpha, tan beta, 1): the consistent form of equation (7), whose printed version swaps the axes.

    Parameters
    ----------
    alpha_rad, beta_rad : array_like
        In-track and cross-track angles, rad, broadcast together.

    Returns
    -------
    numpy.ndarray
        Unit vectors in the spacecraft body frame, shape (..., 3).
    """
    a, b = np.broadcast_arrays(np.asarray(alpha_rad, float), np.asarray(beta_rad, float))
    return unit(np.stack([np.tan(a), np.tan(b), np.ones_like(a)], axis=-1))
