"""The LOS perturbation grid of Wang et al. 2017, section 2.3."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.constants import DEFAULT_HALF_STEPS, DEFAULT_STEP_RAD
from monitor.geometry.frames import los_from_angles


def perturbation_grid(n: int = DEFAULT_HALF_STEPS, step_rad: float = DEFAULT_STEP_RAD) -> np.ndarray:
    """Offsets (i - n) * s, i = 0..2n, in radians: equations (3)-(6); the middle entry is zero."""
    return (np.arange(2 * n + 1) - n) * step_rad


def perturbed_los_sbf(alpha_rad: ArrayLike, beta_rad: ArrayLike, offsets_rad: np.ndarray) -> np.ndarray:
    """The (2n+1) x (2n+1) perturbed SBF unit vectors LOS_ij of each FOV, equation (7) (axes as in (1)-(2)).

    Returns shape alpha.shape + (2n+1, 2n+1, 3); index i perturbs alpha (in-track), j perturbs beta.
    """
    a = np.asarray(alpha_rad, float)[..., None, None] + offsets_rad[:, None]
    b = np.asarray(beta_rad, float)[..., None, None] + offsets_rad[None, :]
    return los_from_angles(a, b)
