"""The CrIS instrument line-of-sight model of an engineering packet (EP), and its inverse.

Wang et al. 2017, section 4.1 (equations 9-23) and table 2, with the conventions that reproduce IDPS
GCRSO from the real EPs (docs/jpss-formats.md 2.2 and 2.3, checked in ``tests/geometry/test_ep_model.py``):

* IOAR (interferometer optical axis reference): a FOV's LOS is ``Ry(pitch) Rz(yaw) [1, 0, 0]`` with
  ``yaw = -(CrosstrackOffset_i + LosRelativeYaw)`` and ``pitch = IntrackOffset_i + LosRelativePitch``.
* IOAR -> SSMF (scene selection mirror frame): ``Ry(IfrBoresightToSsmf pitch) Rz(IfrBoresightToSsmf yaw)``
  (equation 14).
* Mirror normal of FOR k in SSMF: ``Ry(ActualIntrackAnglePitch_k) Rx(ActualCrosstrackAngleRoll_k)
  [-1, 0, 1]/sqrt(2)`` (equation 15); the LOS is reflected on it (equation 16).
* SSMF -> EP SBF: ``T = M(SbfToIar) M(IarToSsmr) M(SsmrToSsmf)`` with ``M = Rx(roll) Ry(pitch) Rz(yaw)``
  (equations 10 and 17-18).
* EP SBF -> spacecraft frame: the mounting ``M(roll, pitch, yaw)`` (the PCT angles, not in the EP).

The spacecraft frame here is the attitude-defined body frame that :mod:`monitor.geometry.frames` calls
SBF: the frame of the inverse geolocation and of the assessment's alpha and beta (equations 1-2).
All angles are radians; EP files hold microradians (:mod:`monitor.sdr.engpkt` converts).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.constants import N_FOR, N_FOV
from monitor.core.errors import DataError
from monitor.geometry.frames import los_angles, los_from_angles, rot_x, rot_y, rot_z, unit

FOV5 = 4  # index of the central FOV, whose LOS defines the FOR's pointing (section 4.1)
_MIRROR_NORMAL_0 = np.array([-1.0, 0.0, 1.0]) / np.sqrt(2.0)


@dataclass(frozen=True)
class EngineeringPacket:
    """The CrIS mapping angles of table 2 (radians), the long-wave FOV geometry and provenance.

    Triples are (roll, pitch, yaw) about (x, y, z); ``ifr_boresight_to_ssmf_rad`` is (yaw, pitch).
    ``sc_to_sbf_rad`` is the instrument mounting on the spacecraft (PCT angles); ``time_stamp_bias_ms``
    is carried for completeness: IDPS already applies it to ``FORTime`` (docs/jpss-formats.md 2.3, point 7).
    """

    satellite: str
    version: str
    fov_crosstrack_offset_rad: np.ndarray
    fov_intrack_offset_rad: np.ndarray
    fov_size_rad: np.ndarray
    los_relative_yaw_rad: float
    los_relative_pitch_rad: float
    ifr_boresight_to_ssmf_rad: tuple
    ssm_crosstrack_roll_rad: np.ndarray
    ssm_intrack_pitch_rad: np.ndarray
    ssmr_to_ssmf_rad: tuple
    iar_to_ssmr_rad: tuple
    sbf_to_iar_rad: tuple
    sc_to_sbf_rad: tuple
    time_stamp_bias_ms: float = 0.0
    provenance: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name, n in (
            ("fov_crosstrack_offset_rad", N_FOV),
            ("fov_intrack_offset_rad", N_FOV),
            ("fov_size_rad", N_FOV),
            ("ssm_crosstrack_roll_rad", N_FOR),
            ("ssm_intrack_pitch_rad", N_FOR),
            ("ifr_boresight_to_ssmf_rad", 2),
            ("ssmr_to_ssmf_rad", 3),
            ("iar_to_ssmr_rad", 3),
            ("sbf_to_iar_rad", 3),
            ("sc_to_sbf_rad", 3),
        ):
            value = np.asarray(getattr(self, name), float)
            if value.shape != (n,):
                raise DataError(f"EP {self.version}: {name} needs {n} values, got shape {value.shape}")
            if not np.all(np.isfinite(value)):
                raise DataError(f"EP {self.version}: {name} has a non-finite value: {value.tolist()}")
            object.__setattr__(self, name, value)
        for name in ("los_relative_yaw_rad", "los_relative_pitch_rad", "time_stamp_bias_ms"):
            if not np.isfinite(float(getattr(self, name))):
                raise DataError(f"EP {self.version}: {name} is not finite")

    def with_ssm_angles(
        self,
        crosstrack_roll_rad: ArrayLike,
        intrack_pitch_rad: ArrayLike,
        version: str | None = None,
        provenance: dict | None = None,
    ) -> EngineeringPacket:
        """A copy with the 2 x 30 scene-mirror angles replaced (the only angles the optimiser changes).

        Parameters
        ----------
        crosstrack_roll_rad, intrack_pitch_rad : array_like
            The scene mirror's angles per FOR, rad, shape (30,).
        version : str, optional
            The new packet's version; the packet's own when None.
        provenance : dict, optional
            What the new angles were derived from, recorded with the packet.

        Returns
        -------
        EngineeringPacket
            The new packet.
        """
        return dataclasses.replace(
            self,
            ssm_crosstrack_roll_rad=np.asarray(crosstrack_roll_rad, float),
            ssm_intrack_pitch_rad=np.asarray(intrack_pitch_rad, float),
            version=self.version if version is None else version,
            provenance=self.provenance if provenance is None else provenance,
        )


def attitude_matrix(roll_rad: ArrayLike, pitch_rad: ArrayLike, yaw_rad: ArrayLike) -> np.ndarray:
    """T = R_x(roll) P_y(pitch) Y_z(yaw), equation (10): the mapping-angle transformation.

    Parameters
    ----------
    roll_rad, pitch_rad, yaw_rad : array_like
        The angles, rad, broadcast together.

    Returns
    -------
    numpy.ndarray
        Rotations, shape (..., 3, 3).
    """
    return rot_x(roll_rad) @ rot_y(pitch_rad) @ rot_z(yaw_rad)


def fov_los_ioar(ep: EngineeringPacket) -> np.ndarray:
    """The unit LOS of FOVs 1..9 in the IOAR from the long-wave FOV offsets and the FOV-5 LOS offset.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    numpy.ndarray
        Unit vectors, shape (9, 3).
    """
    yaw = -(ep.fov_crosstrack_offset_rad + ep.los_relative_yaw_rad)
    pitch = ep.fov_intrack_offset_rad + ep.los_relative_pitch_rad
    return np.einsum("fij,fjk,k->fi", rot_y(pitch), rot_z(yaw), np.array([1.0, 0.0, 0.0]))


def ioar_to_ssmf(ep: EngineeringPacket) -> np.ndarray:
    """P(theta_SSMF) Y(phi_SSMF), equation (14): IOAR vectors to the scene-mirror frame.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    numpy.ndarray
        The rotation, shape (3, 3).
    """
    yaw, pitch = ep.ifr_boresight_to_ssmf_rad
    return rot_y(pitch) @ rot_z(yaw)


def fov_los_ssmf(ep: EngineeringPacket) -> np.ndarray:
    """The unit LOS of each FOV in the SSMF before the mirror, equation (14).

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    numpy.ndarray
        Unit vectors, shape (9, 3).
    """
    return fov_los_ioar(ep) @ ioar_to_ssmf(ep).T


def mirror_normal(crosstrack_roll_rad: ArrayLike, intrack_pitch_rad: ArrayLike) -> np.ndarray:
    """The unit scene-mirror normal in the SSMF, equation (15): P(pitch) R(roll) [-1, 0, 1]/sqrt(2).

    Parameters
    ----------
    crosstrack_roll_rad, intrack_pitch_rad : array_like
        The scene mirror's angles, rad.

    Returns
    -------
    numpy.ndarray
        Unit normals, shape (..., 3).
    """
    return np.einsum(
        "...ij,...jk,k->...i",
        rot_y(np.asarray(intrack_pitch_rad, float)),
        rot_x(np.asarray(crosstrack_roll_rad, float)),
        _MIRROR_NORMAL_0,
    )


def ssm_angles_from_normal(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The scene-mirror angles of a mirror normal: the exact inverse of equation (15).

    With v = R(roll) n0 = (-1, -sin roll, cos roll)/sqrt(2), n_y = -sin(roll)/sqrt(2) gives the roll, and the
    pitch is the turn about y that takes (v_x, v_z) onto (n_x, n_z).

    Parameters
    ----------
    normal : numpy.ndarray
        Unit mirror normals in the SSMF, shape (..., 3).

    Returns
    -------
    crosstrack_roll_rad, intrack_pitch_rad : numpy.ndarray
        The angles, rad.
    """
    n = unit(normal)
    roll = np.arcsin(np.clip(-np.sqrt(2.0) * n[..., 1], -1.0, 1.0))
    pitch = np.arctan2(np.cos(roll), -1.0) - np.arctan2(n[..., 2], n[..., 0])
    return roll, (pitch + np.pi) % (2 * np.pi) - np.pi


def reflect(los: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """The LOS reflected on a mirror, equation (16): l - 2 (l . n) n.

    Parameters
    ----------
    los : numpy.ndarray
        Unit lines of sight, shape (..., 3).
    normal : numpy.ndarray
        The mirror's unit normal in the same frame, broadcast against *los*.

    Returns
    -------
    numpy.ndarray
        The reflected unit vectors, shape (..., 3).
    """
    return los - 2.0 * np.sum(los * normal, axis=-1, keepdims=True) * normal


def ssmf_to_ep_sbf(ep: EngineeringPacket) -> np.ndarray:
    """T_SBF/SSMF = T_SBF/IAR T_IAR/SSMR T_SSMR/SSMF, equation (17), each T as in equation (10).

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    numpy.ndarray
        The rotation, shape (3, 3).
    """
    return (
        attitude_matrix(*ep.sbf_to_iar_rad)
        @ attitude_matrix(*ep.iar_to_ssmr_rad)
        @ attitude_matrix(*ep.ssmr_to_ssmf_rad)
    )


def ep_sbf_to_spacecraft(ep: EngineeringPacket) -> np.ndarray:
    """The instrument mounting: EP SBF vectors to the attitude-defined spacecraft body frame.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    numpy.ndarray
        The rotation, shape (3, 3).
    """
    return attitude_matrix(*ep.sc_to_sbf_rad)


def los_ep_sbf(ep: EngineeringPacket) -> np.ndarray:
    """The unit LOS of every FOR and FOV in the EP's SBF, equations (14)-(18).

    The 3 x 3 pattern turns with the scan angle because every FOV is reflected on the same mirror.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    numpy.ndarray
        Unit vectors, shape (30, 9, 3): every FOR and FOV.
    """
    n = mirror_normal(ep.ssm_crosstrack_roll_rad, ep.ssm_intrack_pitch_rad)  # (30, 3)
    reflected = reflect(fov_los_ssmf(ep)[None, :, :], n[:, None, :])  # (30, 9, 3)
    return reflected @ ssmf_to_ep_sbf(ep).T


def los_spacecraft(ep: EngineeringPacket) -> np.ndarray:
    """The unit LOS of every FOR and FOV in the spacecraft body frame of :mod:`monitor.geometry.frames`.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    numpy.ndarray
        Unit vectors, shape (30, 9, 3): every FOR and FOV.
    """
    return los_ep_sbf(ep) @ ep_sbf_to_spacecraft(ep).T


def ssm_angles_for_los(
    ep: EngineeringPacket, target_los_spacecraft: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The scene-mirror angles that point FOV 5 of each FOR along a target LOS, equations (22)-(23).

    The target goes back to the SSMF, the mirror normal is the unit difference of the reflected and incident
    LOS (its sign chosen to face the incident beam like the EP's own normal), and equation (15) is inverted.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.
    target_los_spacecraft : numpy.ndarray
        The wanted FOV-5 LOS of each FOR in the spacecraft body frame, shape (30, 3).

    Returns
    -------
    crosstrack_roll_rad, intrack_pitch_rad : numpy.ndarray
        The angles, rad, shape (30,).
    """
    target = unit(np.asarray(target_los_spacecraft, float))
    to_ssmf = (ep_sbf_to_spacecraft(ep) @ ssmf_to_ep_sbf(ep)).T
    target_ssmf = target @ to_ssmf.T  # equation (22)
    incident = fov_los_ssmf(ep)[FOV5]
    normal = unit(target_ssmf - incident)  # equation (23)
    old = mirror_normal(ep.ssm_crosstrack_roll_rad, ep.ssm_intrack_pitch_rad)
    normal = np.where(np.sum(normal * old, axis=-1, keepdims=True) < 0, -normal, normal)
    return ssm_angles_from_normal(normal)


def corrected_ssm_angles(
    ep: EngineeringPacket, d_alpha_rad: ArrayLike, d_beta_rad: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """New scene-mirror angles from assessed LOS offsets, equations (19)-(23).

    alpha'_k = alpha_k + d_alpha_k and beta'_k = beta_k + d_beta_k for the FOV-5 LOS of *ep* in the
    spacecraft frame (equations 19-20); the corrected LOS is unit(tan alpha', tan beta', 1) (equation 21 in
    its consistent form) and the mirror angles follow from :func:`ssm_angles_for_los`.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.
    d_alpha_rad, d_beta_rad : array_like
        The assessed in-track and cross-track offsets per FOR, rad, shape (30,).

    Returns
    -------
    crosstrack_roll_rad, intrack_pitch_rad : numpy.ndarray
        The corrected angles, rad, shape (30,).
    """
    alpha, beta = los_angles(los_spacecraft(ep)[:, FOV5])
    target = los_from_angles(alpha + np.asarray(d_alpha_rad, float), beta + np.asarray(d_beta_rad, float))
    return ssm_angles_for_los(ep, target)


def fov5_angles(ep: EngineeringPacket) -> tuple[np.ndarray, np.ndarray]:
    """The in-track and cross-track angles of the FOV-5 LOS of each FOR in the spacecraft frame.

    Parameters
    ----------
    ep : EngineeringPacket
        The engineering packet.

    Returns
    -------
    alpha_rad, beta_rad : numpy.ndarray
        Shape (30,), rad.
    """
    return los_angles(los_spacecraft(ep)[:, FOV5])
