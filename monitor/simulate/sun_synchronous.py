"""Circular sun-synchronous orbits: analytic ECI motion turned into ECEF by the Earth rotation angle.

Each satellite's orbit comes from :mod:`monitor.core.satellites` (altitude, inclination, local time of the
ascending node, phase). :func:`find_pass` picks the start of a pass (ascending or descending through
a latitude, optionally nearest a longitude) so that a simulated case can be put anywhere on the Earth:
tropics by day or night, high latitudes, across the 180 deg meridian.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from monitor.core.errors import DataError
from monitor.core.satellites import NODAL_PERIOD_S, PHASE_EPOCH_UNIX_S, Satellite
from monitor.geometry.wgs84 import A_M, GM_M3_S2, OMEGA_EARTH_RAD_S

# Named passes: (geocentric latitude of the first CrIS granule, ascending). A 14-granule case covers
# ~27 deg of orbit: "arctic" runs from 60 deg N to the orbit's turning point at 81 deg N.
PASSES = {"day": (-14.0, True), "night": (14.0, False), "arctic": (60.0, True), "antarctic": (-60.0, False)}
J2000_UNIX_S = 946728000.0  # 2000-01-01T12:00:00 UTC
DAY_S = 86400.0


def earth_rotation_angle(unix_s: ArrayLike) -> np.ndarray:
    """Earth rotation angle (rad) at UTC seconds since 1970 (UT1 taken as UTC; IERS 2010 eq. 5.15).

    Parameters
    ----------
    unix_s : array_like
        UTC seconds since 1970.

    Returns
    -------
    numpy.ndarray
        rad.
    """
    d = (np.asarray(unix_s, float) - J2000_UNIX_S) / DAY_S
    return 2 * np.pi * ((0.7790572732640 + 0.00273781191135448 * d + d) % 1.0)


def mean_sun_right_ascension(unix_s: ArrayLike) -> np.ndarray:
    """Right ascension (rad) of the mean Sun: its mean longitude 280.460 + 0.9856474 deg/day from J2000
    (the equation of time, < 4.5 deg, is left out: a sun-synchronous node follows the mean Sun).

    Parameters
    ----------
    unix_s : array_like
        UTC seconds since 1970.

    Returns
    -------
    numpy.ndarray
        rad.
    """
    d = (np.asarray(unix_s, float) - J2000_UNIX_S) / DAY_S
    return np.radians((280.460 + 0.9856474 * d) % 360.0)


class CircularOrbit:
    """Circular orbit of *altitude_m* and *inclination_deg*: argument of latitude *u0_rad* (default -14 deg)
    and right ascension of the ascending node *raan_rad* at *t0_unix_s* (UTC seconds since 1970).

    Parameters
    ----------
    t0_unix_s : float
        The epoch, UTC s.
    altitude_m : float
        m.
    inclination_deg : float
        deg.
    u0_rad : float, optional
        Argument of latitude at the epoch, rad.
    raan_rad : float, optional
        Right ascension of the ascending node, rad.
    """

    def __init__(
        self,
        t0_unix_s: float,
        altitude_m: float = 828e3,
        inclination_deg: float = 98.74,
        u0_rad: float = -0.2443461,
        raan_rad: float = 0.0,
    ) -> None:
        self.t0 = float(t0_unix_s)
        self.a = A_M + altitude_m
        self.n = np.sqrt(GM_M3_S2 / self.a**3)
        self.i = np.radians(inclination_deg)
        self.u0 = float(u0_rad)
        self.raan = float(raan_rad)

    @classmethod
    def through(
        cls,
        t0_unix_s: float,
        lon0_deg: float = -160.0,
        u0_deg: float = -14.0,
        altitude_m: float = 828e3,
        inclination_deg: float = 98.74,
    ) -> CircularOrbit:
        """The orbit whose sub-satellite point at *t0_unix_s* is at longitude *lon0_deg*, argument of
        latitude *u0_deg*.

        Parameters
        ----------
        t0_unix_s : float
            The epoch, UTC s.
        lon0_deg : float
            The sub-point's longitude, deg.
        u0_deg : float, optional
            Argument of latitude, deg.
        altitude_m : float, optional
            m.
        inclination_deg : float, optional
            deg.

        Returns
        -------
        CircularOrbit
            The orbit.
        """
        orbit = cls(t0_unix_s, altitude_m, inclination_deg, np.radians(u0_deg), 0.0)
        x, y, _ = orbit._orbit_plane(orbit.u0, 0.0)
        orbit.raan = np.radians(lon0_deg) + earth_rotation_angle(orbit.t0) - np.arctan2(y, x)
        return orbit

    @classmethod
    def of(cls, sat: Satellite, t0_unix_s: float) -> CircularOrbit:
        """The satellite's own orbit at *t0_unix_s*: node from the local time of the ascending node,
        argument of latitude from the phase.

        Parameters
        ----------
        sat : Satellite
            The satellite.
        t0_unix_s : float
            The epoch, UTC s.

        Returns
        -------
        CircularOrbit
            Its orbit.
        """
        orbit = cls(t0_unix_s, sat.altitude_m, sat.inclination_deg)
        orbit.u0 = float(_argument_of_latitude(sat, t0_unix_s))
        orbit.raan = float(_node_right_ascension(sat, t0_unix_s))
        return orbit

    def _orbit_plane(self, u: ArrayLike, raan: ArrayLike) -> np.ndarray:
        ci, si = np.cos(self.i), np.sin(self.i)
        cu, su = np.cos(u), np.sin(u)
        co, so = np.cos(raan), np.sin(raan)
        return np.stack([co * cu - so * su * ci, so * cu + co * su * ci, su * si])

    def state_eci(self, unix_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """ECI position (m) and velocity (m/s), shapes t + (3,).

        Parameters
        ----------
        unix_s : array_like
            UTC seconds since 1970.

        Returns
        -------
        position_m, velocity_m_s : numpy.ndarray
            ECI, shape t + (3,).
        """
        u = self.u0 + self.n * (np.asarray(unix_s, float) - self.t0)
        r = self.a * np.moveaxis(self._orbit_plane(u, self.raan), 0, -1)
        du = np.moveaxis(self._orbit_plane(u + np.pi / 2, self.raan), 0, -1)
        return r, self.a * self.n * du

    def state_ecef(self, unix_s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """ECEF position (m) and velocity (m/s) at UTC seconds since 1970.

        Parameters
        ----------
        unix_s : array_like
            UTC seconds since 1970.

        Returns
        -------
        position_m, velocity_m_s : numpy.ndarray
            ECEF, shape t + (3,).
        """
        r, v = self.state_eci(unix_s)
        theta = earth_rotation_angle(unix_s)
        c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]

        def rot(w: np.ndarray) -> np.ndarray:
            return np.stack(
                [
                    c[..., 0] * w[..., 0] + s[..., 0] * w[..., 1],
                    -s[..., 0] * w[..., 0] + c[..., 0] * w[..., 1],
                    w[..., 2],
                ],
                axis=-1,
            )

        r_e = rot(r)
        v_e = rot(v) - np.cross([0.0, 0.0, OMEGA_EARTH_RAD_S], r_e)
        return r_e, v_e


def _node_right_ascension(sat: Satellite, unix_s: ArrayLike) -> np.ndarray:
    return mean_sun_right_ascension(unix_s) + np.radians((sat.ltan_h - 12.0) * 15.0)


def _argument_of_latitude(sat: Satellite, unix_s: ArrayLike) -> np.ndarray:
    """Mean argument of latitude (rad): the satellite's phase advancing with the shared orbit's period."""
    return (
        np.radians(sat.phase_deg)
        + 2 * np.pi * (np.asarray(unix_s, float) - PHASE_EPOCH_UNIX_S) / NODAL_PERIOD_S
    )


def find_pass(
    sat: Satellite,
    after_unix_s: float,
    lat_deg: float,
    ascending: bool = True,
    lon_deg: float | None = None,
    days: int = 16,
    step_s: float = 5.0,
) -> float:
    """UTC seconds of the satellite's sub-point crossing *lat_deg* (geocentric, northbound when
    *ascending*) after *after_unix_s*; with *lon_deg*, the crossing nearest that longitude within
    *days* (16: the JPSS repeat cycle, so every longitude comes within ~1 deg). ValueError if the
    latitude is beyond the orbit's reach.

    Parameters
    ----------
    sat : Satellite
        The satellite.
    after_unix_s : float
        UTC s.
    lat_deg : float
        Geocentric latitude, deg.
    ascending : bool, optional
        Northbound.
    lon_deg : float, optional
        The crossing nearest this longitude, deg.
    days : int, optional
        Searched within these days.
    step_s : float, optional
        The search's step, s.

    Returns
    -------
    float
        UTC s.
    """
    if abs(np.sin(np.radians(lat_deg))) >= np.sin(np.radians(180.0 - sat.inclination_deg)):
        raise DataError(f"latitude {lat_deg} deg is beyond the reach of the {sat.name} orbit")
    t = after_unix_s + np.arange(0.0, (days if lon_deg is not None else 1) * DAY_S, step_s)
    u = _argument_of_latitude(sat, t)
    i = np.radians(sat.inclination_deg)
    lat = np.arcsin(np.sin(i) * np.sin(u))
    northbound = np.cos(u) * np.sin(i) > 0
    target = np.radians(lat_deg)
    cross = np.flatnonzero((lat[:-1] - target) * (lat[1:] - target) <= 0)
    cross = cross[northbound[cross] == ascending]
    frac = (target - lat[cross]) / (lat[cross + 1] - lat[cross])
    t_cross = t[cross] + frac * step_s
    if lon_deg is None:
        return float(t_cross[0])
    raan = _node_right_ascension(sat, t_cross)
    u_c = _argument_of_latitude(sat, t_cross)
    ra = raan + np.arctan2(np.cos(i) * np.sin(u_c), np.cos(u_c))
    lon = ra - earth_rotation_angle(t_cross)
    miss = np.angle(np.exp(1j * (lon - np.radians(lon_deg))))
    return float(t_cross[np.argmin(np.abs(miss))])
