"""Each satellite's orbit from the satellite table, and passes anywhere on the Earth."""

import datetime as dt

import numpy as np
import pytest

from monitor.core.errors import DataError
from monitor.core.satellites import SATELLITES, satellite
from monitor.geometry import wgs84
from monitor.simulate.sun_synchronous import CircularOrbit, find_pass

T0 = dt.datetime(2025, 3, 1, tzinfo=dt.timezone.utc).timestamp()


def _sub_point(orbit, t):
    r, v = orbit.state_ecef(t)
    lat, lon, h = wgs84.ecef_to_geodetic(r)
    return np.degrees(lat), np.degrees(lon), h, v


@pytest.mark.parametrize(
    "lat,ascending,lon",
    [
        (-14, True, None),
        (14, False, None),
        (60, True, None),
        (-60, False, None),
        (14, False, 180.0),
        (0, True, -75.0),
    ],
)
def test_find_pass_puts_the_satellite_where_asked(lat, ascending, lon):
    sat = satellite("j01")
    t = find_pass(sat, T0, lat, ascending, lon)
    orbit = CircularOrbit.of(sat, t)
    glat, glon, h, v = _sub_point(orbit, t)
    assert glat == pytest.approx(lat, abs=0.3)  # geodetic vs geocentric latitude
    assert (v[2] > 0) == ascending
    assert h == pytest.approx(sat.altitude_m, abs=25e3)  # the ellipsoid is not a sphere
    if lon is not None:
        assert (
            abs((glon - lon + 180) % 360 - 180) < 1.5
        )  # the 16-day repeat brings every longitude within ~1 deg


def test_satellites_have_distinct_orbits_and_local_time():
    orbits = {s: CircularOrbit.of(SATELLITES[s], T0) for s in SATELLITES}
    assert orbits["npp"].a != orbits["j01"].a
    u = {s: np.degrees(o.u0) % 360 for s, o in orbits.items()}
    assert (u["j02"] - u["npp"]) % 360 == pytest.approx(90, abs=0.01)  # NOAA-21 a quarter orbit ahead
    assert (u["npp"] - u["j01"]) % 360 == pytest.approx(90, abs=0.01)  # NOAA-20 opposite NOAA-21
    sat = satellite("npp")  # an ascending equator crossing is at ~13:30 local solar time
    t = find_pass(sat, T0, 0.0, True)
    _, lon, _, _ = _sub_point(CircularOrbit.of(sat, t), t)
    utc_h = (t % 86400) / 3600
    assert (utc_h + lon / 15) % 24 == pytest.approx(13.5, abs=0.3)


def test_unreachable_latitude_and_unknown_satellite():
    with pytest.raises(DataError, match="beyond the reach"):
        find_pass(satellite("npp"), T0, 85.0)
    with pytest.raises(DataError, match="unknown satellite 'metop'"):
        satellite("metop")
