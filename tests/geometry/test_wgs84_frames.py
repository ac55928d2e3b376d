import numpy as np
import pytest

from monitor.geometry import frames, wgs84
from monitor.simulate.sun_synchronous import CircularOrbit, earth_rotation_angle


def test_geodetic_ecef_round_trip():
    rng = np.random.default_rng(0)
    lat = rng.uniform(-1.5, 1.5, 1000)
    lon = rng.uniform(-np.pi, np.pi, 1000)
    h = rng.uniform(-100, 900e3, 1000)
    lat2, lon2, h2 = wgs84.ecef_to_geodetic(wgs84.geodetic_to_ecef(lat, lon, h))
    assert np.max(np.abs(lat2 - lat)) < 1e-10 and np.max(np.abs(h2 - h)) < 1e-3
    assert np.max(np.abs(np.angle(np.exp(1j * (lon2 - lon))))) < 1e-12


def test_ray_meets_ellipsoid_and_zenith_azimuth_invert_look_vector():
    ground = wgs84.geodetic_to_ecef(0.3, -2.0, 0.0)
    look = wgs84.look_vector_ecef(0.3, -2.0, np.radians(40.0), np.radians(-120.0))
    sat = ground + 1.2e6 * look
    t = wgs84.intersect_ellipsoid(sat, -look)
    assert t == pytest.approx(1.2e6, abs=1e-3)
    zen, az, rng = wgs84.zenith_azimuth(ground, sat)
    assert np.degrees(zen) == pytest.approx(40.0) and np.degrees(az) == pytest.approx(-120.0)
    assert np.isnan(wgs84.intersect_ellipsoid(sat, look))


def test_rotations_follow_paper_equations():
    r = frames.rot_x(0.3)
    assert np.allclose(r @ r.T, np.eye(3)) and r[1, 2] == pytest.approx(-np.sin(0.3))
    assert frames.rot_y(0.2)[0, 2] == pytest.approx(np.sin(0.2))
    assert frames.rot_z(0.1)[1, 0] == pytest.approx(np.sin(0.1))
    a, b = frames.los_angles(frames.los_from_angles(0.01, -0.8))
    assert a == pytest.approx(0.01) and b == pytest.approx(-0.8)


def _rot3(theta):
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])  # ECI -> ECEF


def test_ocs_in_ecef_with_inertial_velocity_equals_eci_construction():
    """The ECEF shortcut of frames.ocs_axes_ecef gives the same LOS angles as building the OCS in ECI."""
    orbit = CircularOrbit.through(1.7e9)
    t = 1.7e9 + np.linspace(0, 600, 7)
    r_eci, v_eci = orbit.state_eci(t)
    r_ecef, v_ecef = orbit.state_ecef(t)
    rng = np.random.default_rng(1)
    los_ecef = frames.unit(-r_ecef + rng.normal(0, 3e5, r_ecef.shape))
    att = rng.normal(0, 1e-5, (len(t), 3))
    m = frames.sbf_to_ecef(r_ecef, v_ecef, att)
    los_sbf = np.einsum("kji,kj->ki", m, los_ecef)
    for k, theta in enumerate(earth_rotation_angle(t)):
        rot = _rot3(theta)
        los_eci = rot.T @ los_ecef[k]
        # independent ECI OCS: geodetic nadir (rotated from ECEF), y = z x v_eci, x = y x z
        z = rot.T @ (-wgs84.geodetic_up(r_ecef[k]))
        y = frames.unit(np.cross(z, v_eci[k]))
        x = np.cross(y, z)
        ocs = np.stack([x, y, z], axis=1)
        expected = frames.sbf_to_ocs(*att[k]).T @ (ocs.T @ los_eci)
        assert np.max(np.abs(expected - los_sbf[k])) < 1e-9  # < 1 nrad


def test_ecef_velocity_alone_would_be_wrong():
    orbit = CircularOrbit.through(1.7e9)
    r, v = orbit.state_ecef(1.7e9)
    good = frames.ocs_axes_ecef(r, v)
    naive_y = frames.unit(np.cross(-wgs84.geodetic_up(r), v))
    assert np.degrees(np.arccos(np.clip(good[:, 1] @ naive_y, -1, 1))) > 1.0  # ~3-4 deg of yaw
