"""A circular sun-synchronous-like orbit: analytic ECI motion turned into ECEF by the Earth rotation angle."""

from __future__ import annotations

import numpy as np

from monitor.geometry.wgs84 import A_M, GM_M3_S2, OMEGA_EARTH_RAD_S

J2000_UNIX_S = 946728000.0  # 2000-01-01T12:00:00 UTC


def earth_rotation_angle(unix_s):
    """Earth rotation angle (rad) at UTC seconds since 1970 (UT1 taken as UTC; IERS 2010 eq. 5.15)."""
    d = (np.asarray(unix_s, float) - J2000_UNIX_S) / 86400.0
    return 2 * np.pi * ((0.7790572732640 + 0.00273781191135448 * d + d) % 1.0)


class CircularOrbit:
    """Circular orbit of *altitude_m* and *inclination_deg*; argument of latitude *u0_deg* at *t0_unix_s*.

    The ascending node's right ascension is chosen so the sub-satellite point at t0 is at *lon0_deg*.
    """

    def __init__(self, t0_unix_s, altitude_m=828e3, inclination_deg=98.74, u0_deg=-14.0, lon0_deg=-160.0):
        self.t0 = float(t0_unix_s)
        self.a = A_M + altitude_m
        self.n = np.sqrt(GM_M3_S2 / self.a**3)
        self.i = np.radians(inclination_deg)
        self.u0 = np.radians(u0_deg)
        x, y, _ = self._orbit_plane(self.u0, 0.0)
        ra_of_point = np.arctan2(y, x)
        self.raan = np.radians(lon0_deg) + earth_rotation_angle(self.t0) - ra_of_point

    def _orbit_plane(self, u, raan):
        ci, si = np.cos(self.i), np.sin(self.i)
        cu, su = np.cos(u), np.sin(u)
        co, so = np.cos(raan), np.sin(raan)
        return np.stack([co * cu - so * su * ci, so * cu + co * su * ci, su * si])

    def state_eci(self, unix_s):
        """ECI position (m) and velocity (m/s), shapes t + (3,)."""
        u = self.u0 + self.n * (np.asarray(unix_s, float) - self.t0)
        r = self.a * np.moveaxis(self._orbit_plane(u, self.raan), 0, -1)
        du = np.moveaxis(self._orbit_plane(u + np.pi / 2, self.raan), 0, -1)
        return r, self.a * self.n * du

    def state_ecef(self, unix_s):
        """ECEF position (m) and velocity (m/s) at UTC seconds since 1970."""
        r, v = self.state_eci(unix_s)
        theta = earth_rotation_angle(unix_s)
        c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]

        def rot(w):
            return np.stack([c[..., 0] * w[..., 0] + s[..., 0] * w[..., 1],
                             -s[..., 0] * w[..., 0] + c[..., 0] * w[..., 1], w[..., 2]], axis=-1)
        r_e = rot(r)
        v_e = rot(v) - np.cross([0.0, 0.0, OMEGA_EARTH_RAD_S], r_e)
        return r_e, v_e
