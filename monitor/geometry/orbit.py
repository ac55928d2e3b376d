"""Short-arc propagation of the spacecraft state in the rotating ECEF frame (two-body + J2).

IDPS gives SCPosition/SCVelocity at each scan's MidTime; a FOR is up to ~3 s away. A straight line
r + v dt is ~30 m off at the scan ends (docs/jpss-formats.md 2.3), so the state is integrated with RK4.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.geometry.wgs84 import A_M, GM_M3_S2, J2, OMEGA_EARTH_RAD_S

_OMEGA = np.array([0.0, 0.0, OMEGA_EARTH_RAD_S])


def acceleration_ecef(r_m: ArrayLike, v_m_s: ArrayLike) -> np.ndarray:
    """The acceleration in the rotating Earth frame: gravity with J2, Coriolis and centrifugal terms.

    Parameters
    ----------
    r_m : array_like
        Positions, ECEF, m, shape (..., 3).
    v_m_s : array_like
        Velocities relative to the rotating Earth, ECEF, m/s, shape (..., 3).

    Returns
    -------
    numpy.ndarray
        Accelerations, ECEF, m/s^2, shape (..., 3).
    """
    r = np.asarray(r_m, float)
    rn = np.linalg.norm(r, axis=-1, keepdims=True)
    z2 = (r[..., 2:3] / rn) ** 2
    k = 1.5 * J2 * (A_M / rn) ** 2
    g = -GM_M3_S2 * r / rn**3
    g = g * np.concatenate([1 + k * (1 - 5 * z2), 1 + k * (1 - 5 * z2), 1 + k * (3 - 5 * z2)], axis=-1)
    coriolis = -2.0 * np.cross(_OMEGA, np.asarray(v_m_s, float))
    centrifugal = -np.cross(_OMEGA, np.cross(_OMEGA, r))
    return g + coriolis + centrifugal


def propagate(
    r_m: ArrayLike, v_m_s: ArrayLike, dt_s: ArrayLike, steps: int = 8
) -> tuple[np.ndarray, np.ndarray]:
    """The ECEF state after *dt_s*, by fourth-order Runge-Kutta steps.

    Parameters
    ----------
    r_m, v_m_s : array_like
        The state: ECEF position (m) and velocity (m/s), shape (..., 3).
    dt_s : array_like
        Time to propagate, s, broadcast per row.
    steps : int, optional
        RK4 steps of dt_s / steps each.

    Returns
    -------
    r_m, v_m_s : numpy.ndarray
        The state after *dt_s*.
    """
    r = np.array(r_m, float)
    v = np.array(v_m_s, float)
    h = (np.asarray(dt_s, float) / steps)[..., None]
    for _ in range(steps):
        k1v, k1r = acceleration_ecef(r, v), v
        k2v = acceleration_ecef(r + 0.5 * h * k1r, v + 0.5 * h * k1v)
        k2r = v + 0.5 * h * k1v
        k3v = acceleration_ecef(r + 0.5 * h * k2r, v + 0.5 * h * k2v)
        k3r = v + 0.5 * h * k2v
        k4v = acceleration_ecef(r + h * k3r, v + h * k3v)
        k4r = v + h * k3v
        r = r + h / 6.0 * (k1r + 2 * k2r + 2 * k3r + k4r)
        v = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
    return r, v


def state_at(
    times_us: ArrayLike, mid_times_us: ArrayLike, positions_m: ArrayLike, velocities_m_s: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """The spacecraft's ECEF state at each of *times_us*, propagated from the nearest scan's MidTime state.

    Parameters
    ----------
    times_us : array_like
        The times wanted, IET us.
    mid_times_us : array_like
        Each scan's middle time, IET us, shape (n,).
    positions_m, velocities_m_s : array_like
        The spacecraft's ECEF position (m) and velocity (m/s) at each scan's middle, shape (n, 3).

    Returns
    -------
    r_m, v_m_s : numpy.ndarray
        ECEF position (m) and velocity (m/s), shape ``times_us.shape + (3,)``.
    """
    t = np.asarray(times_us, np.int64)
    mid = np.asarray(mid_times_us, np.int64)
    nearest = np.argmin(np.abs(t[..., None] - mid), axis=-1)
    dt = (t - mid[nearest]) * 1e-6
    return propagate(np.asarray(positions_m, float)[nearest], np.asarray(velocities_m_s, float)[nearest], dt)


def interpolate_per_scan(times_us: ArrayLike, mid_times_us: ArrayLike, values: ArrayLike) -> np.ndarray:
    """Per-scan values interpolated linearly to *times_us* (extrapolated at the ends).

    Parameters
    ----------
    times_us : array_like
        The times wanted, IET us.
    mid_times_us : array_like
        Each scan's middle time, IET us, shape (n,).
    values : array_like
        The per-scan values (an attitude: roll, pitch, yaw, rad), shape (n, k).

    Returns
    -------
    numpy.ndarray
        Shape ``times_us.shape + (k,)``, in the values' unit.
    """
    t = np.asarray(times_us, np.int64).astype(float)
    mid = np.asarray(mid_times_us, np.int64).astype(float)
    vals = np.asarray(values, float)
    if len(mid) == 1:
        return np.broadcast_to(vals[0], t.shape + vals.shape[1:]).copy()
    i = np.clip(np.searchsorted(mid, t) - 1, 0, len(mid) - 2)
    w = ((t - mid[i]) / (mid[i + 1] - mid[i]))[..., None]
    return vals[i] * (1 - w) + vals[i + 1] * w
