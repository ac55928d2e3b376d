"""Nominal scan geometry of CrIS and VIIRS I-band as lines of sight in the spacecraft body frame (SBF).

SBF axes: x along track, y to the right of track, z toward nadir. A scan angle theta turns the
boresight about x so that the cross-track angle beta = atan(y/z) equals theta (FOR 1 on the left).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.constants import (
    DEFAULT_STEP_RAD,
    FOV_SPACING_RAD,
    N_FOR,
    N_FOV,
    VIIRS_COLUMNS,
    VIIRS_DETECTORS,
    VIIRS_SCAN_US,
)
from monitor.geometry.frames import rot_x, unit

CRIS_FOR_STEP_RAD = np.radians(3.3333)
CRIS_FOR_DT_US = 200_000
CRIS_MID_OFFSET_US = 2_899_989

VIIRS_SCAN_S = VIIRS_SCAN_US * 1e-6
VIIRS_ZONE_COLUMNS = (1280, 736, 2368, 736, 1280)  # aggregation zones, output columns (VcstGeoParameters.h)
VIIRS_ZONE_AGGREGATION = (1, 2, 3, 2, 1)
VIIRS_NATIVE_RAD = 155.2e-6  # along-scan native sample; 12608 samples span +-56 deg
VIIRS_DETECTOR_RAD = DEFAULT_STEP_RAD  # one I-band pixel seen from 833 km
VIIRS_EARTH_VIEW_S = 0.556  # the 112 deg Earth-view sector of the 1.7864 s rotation


def cris_scan_angles_rad() -> np.ndarray:
    """Scan angle of FOR 1..30 (rad), -48.33 deg to +48.33 deg.

    Returns
    -------
    numpy.ndarray
        Shape (30,), rad.
    """
    return (np.arange(N_FOR) - (N_FOR - 1) / 2) * CRIS_FOR_STEP_RAD


def cris_fov_offsets_rad() -> tuple[np.ndarray, np.ndarray]:
    """(in_track, cross_track) offsets (rad) of FOV 1..9 at nadir: FOV 7-9 ahead, FOV 1, 4, 7 on the left.

    Returns
    -------
    in_track_rad, cross_track_rad : numpy.ndarray
        Shape (9,).
    """
    f = np.arange(N_FOV)
    return (f // 3 - 1) * FOV_SPACING_RAD, (f % 3 - 1) * FOV_SPACING_RAD


def cris_los_sbf(d_alpha_rad: ArrayLike | None = None, d_beta_rad: ArrayLike | None = None) -> np.ndarray:
    """Nominal CrIS LOS (30, 9, 3) in the SBF, optionally turned per FOR by (d_alpha, d_beta) (30,) rad.

    The 3x3 pattern turns with the scan angle (the scene mirror rotates about the optical axis).

    Parameters
    ----------
    d_alpha_rad, d_beta_rad : array_like, optional
        Per FOR turns, rad, shape (30,).

    Returns
    -------
    numpy.ndarray
        Unit vectors, shape (30, 9, 3).
    """
    theta = cris_scan_angles_rad()
    da, dc = cris_fov_offsets_rad()
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    a = c * da - s * dc
    b = s * da + c * dc
    local = unit(np.stack([np.tan(a), np.tan(b), np.ones_like(a)], axis=-1))
    los = np.einsum("kij,kfj->kfi", rot_x(-theta), local)
    if d_alpha_rad is None and d_beta_rad is None:
        return los
    zero = np.zeros(N_FOR)
    return turned(
        los,
        np.asarray(d_alpha_rad if d_alpha_rad is not None else zero)[..., None],
        np.asarray(d_beta_rad if d_beta_rad is not None else zero)[..., None],
    )


def turned(los_sbf: np.ndarray, d_alpha_rad: ArrayLike, d_beta_rad: ArrayLike) -> np.ndarray:
    """Unit LOS (..., 3) in the SBF turned by (d_alpha, d_beta) rad (broadcast over ``los_sbf[..., 0]``):
    alpha = atan(x/z) in-track and beta = atan(y/z) cross-track (equations 1-2) grow by them.

    Parameters
    ----------
    los_sbf : numpy.ndarray
        Unit LOS, shape (..., 3).
    d_alpha_rad, d_beta_rad : array_like
        The turns, rad.

    Returns
    -------
    numpy.ndarray
        Unit vectors, shape (..., 3).
    """
    alpha = np.arctan2(los_sbf[..., 0], los_sbf[..., 2]) + d_alpha_rad
    beta = np.arctan2(los_sbf[..., 1], los_sbf[..., 2]) + d_beta_rad
    return unit(np.stack([np.tan(alpha), np.tan(beta), np.ones_like(alpha)], axis=-1))


def viirs_column_geometry() -> tuple[np.ndarray, np.ndarray]:
    """Scan angle (rad) and time within the Earth view (s) of each of the 6400 I-band columns.

    Returns
    -------
    scan_angle_rad, time_s : numpy.ndarray
        Shape (6400,).
    """
    agg = np.repeat(VIIRS_ZONE_AGGREGATION, VIIRS_ZONE_COLUMNS)
    native_end = np.cumsum(agg)
    centre = native_end - agg / 2.0
    total = native_end[-1]
    return (centre - total / 2.0) * VIIRS_NATIVE_RAD, centre / total * VIIRS_EARTH_VIEW_S


def viirs_bowtie_deleted() -> np.ndarray:
    """(32, 6400) mask of on-board bow-tie deleted I-band pixels (docs/jpss-formats.md 3).

    Returns
    -------
    numpy.ndarray
        bool, shape (32, 6400).
    """
    mask = np.zeros((VIIRS_DETECTORS, VIIRS_COLUMNS), bool)
    for rows, n in (((0, 1, 30, 31), 2016), ((2, 3, 28, 29), 1280)):
        for r in rows:
            mask[r, :n] = True
            mask[r, -n:] = True
    return mask


def viirs_detector_angles_rad() -> np.ndarray:
    """In-track angle (rad) of the 32 detectors; detector 0 looks furthest back.

    Returns
    -------
    numpy.ndarray
        Shape (32,), rad.
    """
    return (np.arange(VIIRS_DETECTORS) - (VIIRS_DETECTORS - 1) / 2) * VIIRS_DETECTOR_RAD
