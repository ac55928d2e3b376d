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
    """Acceleration (m/s^2) in the rotating frame: gravity with J2, Coriolis and centrifugal terms."""
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
    """ECEF state after *dt_s* seconds (broadcast per row), by *steps* RK4 steps of dt_s/steps each."""
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
    """Spacecraft ECEF state at each of *times_us* (IET microseconds), from the nearest scan's MidTime state.

    *mid_times_us* (n,) with *positions_m*/*velocities_m_s* (n, 3); returns (r, v) shaped times + (3,).
    """
    t = np.asarray(times_us, np.int64)
    mid = np.asarray(mid_times_us, np.int64)
    nearest = np.argmin(np.abs(t[..., None] - mid), axis=-1)
    dt = (t - mid[nearest]) * 1e-6
    return propagate(np.asarray(positions_m, float)[nearest], np.asarray(velocities_m_s, float)[nearest], dt)


def interpolate_per_scan(times_us: ArrayLike, mid_times_us: ArrayLike, values: ArrayLike) -> np.ndarray:
    """Linear interpolation (extrapolation at the ends) of per-scan *values* (n, k) to *times_us*."""
    t = np.asarray(times_us, np.int64).astype(float)
    mid = np.asarray(mid_times_us, np.int64).astype(float)
    vals = np.asarray(values, float)
    if len(mid) == 1:
        return np.broadcast_to(vals[0], t.shape + vals.shape[1:]).copy()
    i = np.clip(np.searchsorted(mid, t) - 1, 0, len(mid) - 2)
    w = ((t - mid[i]) / (mid[i + 1] - mid[i]))[..., None]
    return vals[i] * (1 - w) + vals[i + 1] * w
