"""The synthetic Earth's terrain and where lines of sight meet it."""

import numpy as np
import pytest

from monitor.geometry import wgs84
from monitor.simulate.scene import MAX_HEIGHT_M, MAX_SLOPE, Scene


@pytest.fixture(scope="module")
def scene():
    return Scene(3, land_fraction=0.4, terrain=True)


def test_terrain_heights_land_and_slopes(scene):
    rng = np.random.default_rng(0)
    lat, lon = np.arcsin(rng.uniform(-1, 1, 200_000)), rng.uniform(-np.pi, np.pi, 200_000)
    h = scene.height_m(lat, lon)
    land = h > 0
    assert 0.3 < land.mean() < 0.5 and h.max() <= MAX_HEIGHT_M and h.min() == 0.0
    assert 1000 < np.percentile(h[land], 75) and np.percentile(h[land], 99) > 3000  # ranges of 1-4 km
    step = 200.0 / wgs84.A_M  # slopes on a 200 m grid around a high point
    k = np.argmax(h)
    la, lo = np.meshgrid(
        lat[k] + step * np.arange(-50, 51), lon[k] + step * np.arange(-50, 51), indexing="ij"
    )
    gy, gx = np.gradient(scene.height_m(la, lo), 200.0, 200.0 * np.cos(lat[k]))
    assert np.hypot(gx, gy).max() < MAX_SLOPE * 1.1
    assert np.all(Scene(3).height_m(lat[:10], lon[:10]) == 0)  # no terrain unless asked


def test_scene_is_continuous_across_the_antimeridian_and_poles(scene):
    eps = 1e-9  # 1 cm either side of the antimeridian
    lat = np.linspace(-1.2, 1.2, 50)
    east = scene.temperature_k(lat, np.full(50, np.pi - eps))
    west = scene.temperature_k(lat, np.full(50, -np.pi + eps))
    assert np.max(np.abs(east - west)) < 0.05
    pole = scene.temperature_k(np.full(8, np.pi / 2 - 1e-7), np.linspace(-np.pi, np.pi, 8))
    assert np.ptp(pole) < 0.05


def test_rays_meet_the_terrain_on_their_line(scene):
    rng = np.random.default_rng(1)
    sat = wgs84.geodetic_to_ecef(0.6, 2.0, 833e3)
    ground = wgs84.geodetic_to_ecef(
        0.6 + rng.uniform(-0.15, 0.15, 20_000), 2.0 + rng.uniform(-0.2, 0.2, 20_000)
    )
    los = (ground - sat) / np.linalg.norm(ground - sat, axis=1, keepdims=True)
    t, lat, lon, h = scene.intersect(sat, los)
    point = wgs84.geodetic_to_ecef(lat, lon, h)
    assert np.allclose(point, sat + t[:, None] * los, atol=0.01)  # on the ray
    assert np.abs(h - scene.height_m(lat, lon)).max() < 1.0  # on the terrain
    assert (h > 500).mean() > 0.1
    t0 = wgs84.intersect_ellipsoid(sat, los)
    assert np.all(t <= t0 + 1e-6) and np.all(t[h > 1] < t0[h > 1] - 0.5)  # met before the ellipsoid over land
    assert np.allclose(t[h < 1e-3], t0[h < 1e-3], atol=0.01)  # at the ellipsoid over the sea
