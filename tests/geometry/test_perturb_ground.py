import numpy as np
import pytest

from monitor.geometry import frames, perturb
from monitor.geometry.ground import offset_km
from monitor.simulate.sun_synchronous import CircularOrbit


def test_grid_is_the_papers():
    g = perturb.perturbation_grid()
    assert len(g) == 21 and g[10] == 0.0
    assert g[1] - g[0] == pytest.approx(375.0 / 833000.0)


def test_perturbed_los_centre_is_the_original_and_axes_are_consistent():
    los = perturb.perturbed_los_sbf(np.array([0.01]), np.array([0.5]), perturb.perturbation_grid())
    assert los.shape == (1, 21, 21, 3)
    a, b = frames.los_angles(los[0])
    assert a[10, 10] == pytest.approx(0.01) and b[10, 10] == pytest.approx(0.5)
    assert np.allclose(np.diff(a, axis=0), 375.0 / 833000.0)  # i moves alpha (in-track)
    assert np.allclose(np.diff(b, axis=1), 375.0 / 833000.0)  # j moves beta (cross-track)


def test_offsets_in_km_at_nadir_and_edge():
    orbit = CircularOrbit.through(1.7e9)
    r, v = orbit.state_ecef(1.7e9)
    m = frames.sbf_to_ecef(r, v, np.zeros(3))
    h = np.linalg.norm(r) - 6378137.0
    # the ground track (ECEF) is yawed ~4 deg from the SBF x axis (inertial velocity): a pure in-track
    # turn shows a small cross-track component on the ground
    it, ct = offset_km(r, m, 0.0, 0.0, v, 1e-3, 0.0)
    assert it == pytest.approx(h * 1e-3 / 1e3, rel=0.02) and 0.02 < abs(ct) < 0.07
    it, ct = offset_km(r, m, 0.0, 0.0, v, 0.0, 1e-3)
    assert ct == pytest.approx(h * 1e-3 / 1e3, rel=0.02) and 0.02 < abs(it) < 0.07
    # at the end of scan a cross-track turn stretches on the ground (the paper's 1752 urad ~ 4 km)
    _, ct_edge = offset_km(r, m, 0.0, np.radians(48.3), v, 0.0, 1752e-6)
    assert 3.5 < ct_edge < 5.0
