"""Nominal scan geometry of CrIS and VIIRS (I- and M-band grids) as lines of sight in the spacecraft body
frame (SBF).

SBF axes: x along track, y to the right of track, z toward nadir. A scan angle theta turns the
boresight about x so that the cross-track angle beta = atan(y/z) equals theta (FOR 1 on the left).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.bands import GRIDS, ZONE_AGGREGATION, ViirsGrid
from monitor.core.constants import FOV_SPACING_RAD, N_FOR, N_FOV, VIIRS_SCAN_US
from monitor.geometry.frames import rot_x, unit

CRIS_FOR_STEP_RAD = np.radians(3.3333)
CRIS_FOR_DT_US = 200_000
CRIS_MID_OFFSET_US = 2_899_989

VIIRS_SCAN_S = VIIRS_SCAN_US * 1e-6
I_GRID = GRIDS["I"]
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


def viirs_column_geometry(grid: ViirsGrid = I_GRID) -> tuple[np.ndarray, np.ndarray]:
    """Scan angle (rad) and time within the Earth view (s) of each output column of a grid (6400 I-band,
    3200 M-band): the centre of the native samples it aggregates.

    Parameters
    ----------
    grid : ViirsGrid, optional
        The I-band grid (default) or the M-band grid.

    Returns
    -------
    scan_angle_rad, time_s : numpy.ndarray
        Shape (columns,).
    """
    agg = np.repeat(ZONE_AGGREGATION, grid.zone_columns)
    native_end = np.cumsum(agg)
    centre = native_end - agg / 2.0
    total = native_end[-1]
    return (centre - total / 2.0) * grid.native_rad, centre / total * VIIRS_EARTH_VIEW_S


def viirs_bowtie_deleted(grid: ViirsGrid = I_GRID) -> np.ndarray:
    """(detectors, columns) mask of a grid's on-board bow-tie deleted pixels (docs/jpss-formats.md 3).

    Parameters
    ----------
    grid : ViirsGrid, optional
        The I-band grid (default) or the M-band grid.

    Returns
    -------
    numpy.ndarray
        bool, shape (detectors, columns).
    """
    mask = np.zeros((grid.detectors, grid.columns), bool)
    for rows, n in grid.bowtie:
        for r in rows:
            mask[r, :n] = True
            mask[r, -n:] = True
    return mask


def viirs_detector_angles_rad(grid: ViirsGrid = I_GRID) -> np.ndarray:
    """In-track angle (rad) of a grid's detectors (32 I-band, 16 M-band); detector 0 looks furthest back.

    Parameters
    ----------
    grid : ViirsGrid, optional
        The I-band grid (default) or the M-band grid.

    Returns
    -------
    numpy.ndarray
        Shape (detectors,), rad.
    """
    return (np.arange(grid.detectors) - (grid.detectors - 1) / 2) * grid.detector_rad
