"""The LOS perturbation grid of Wang et al. 2017, section 2.3."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.constants import DEFAULT_HALF_STEPS, DEFAULT_STEP_RAD
from monitor.geometry.frames import los_from_angles


def perturbation_grid(n: int = DEFAULT_HALF_STEPS, step_rad: float = DEFAULT_STEP_RAD) -> np.ndarray:
    """The offsets (i - n) s, i = 0..2n, equations (3)-(6); the middle entry is zero.

    Parameters
    ----------
    n : int, optional
        Perturbations on each side of zero (``assessment.half_steps``).
    step_rad : float, optional
        The step s, rad (375 m at nadir from 833 km, ~450 urad).

    Returns
    -------
    numpy.ndarray
        The 2n + 1 offsets, rad.
    """
    return (np.arange(2 * n + 1) - n) * step_rad


def perturbed_los_sbf(alpha_rad: ArrayLike, beta_rad: ArrayLike, offsets_rad: np.ndarray) -> np.ndarray:
    """The (2n+1) x (2n+1) perturbed SBF unit vectors LOS_ij of each FOV, equation (7).

    Index i perturbs alpha (in-track), j perturbs beta (cross-track), with the axes as in equations (1)-(2).

    Parameters
    ----------
    alpha_rad, beta_rad : array_like
        Each FOV's in-track and cross-track angles in the spacecraft body frame, rad.
    offsets_rad : numpy.ndarray
        The 2n + 1 offsets (:func:`perturbation_grid`), rad.

    Returns
    -------
    numpy.ndarray
        Shape ``alpha_rad.shape + (2n+1, 2n+1, 3)``: unit vectors in the spacecraft body frame.
    """
    a = np.asarray(alpha_rad, float)[..., None, None] + offsets_rad[:, None]
    b = np.asarray(beta_rad, float)[..., None, None] + offsets_rad[None, :]
    return los_from_angles(a, b)
