"""Clouds with height in the simulator: the height laws, the cloud surface, and rays that meet the first
cloud they pass."""

import numpy as np
import pytest

from monitor.core.errors import DataError
from monitor.geometry import wgs84
from monitor.simulate import CIRRUS_BASE_M
from monitor.simulate import case as sim_module
from monitor.simulate import scan_geometry as ins
from monitor.simulate import scene as scene_module
from monitor.simulate.case import SimulationSpec, Simulator
from monitor.simulate.clouds import CEILING_M, CloudHeights
from monitor.simulate.scene import Scene, Wind


def test_the_laws_turn_a_top_temperature_into_a_height():
    lapse = CloudHeights.parse("lapse:6.5")
    assert lapse.top_height_m(235.0, 300.0) == pytest.approx(10_000.0, abs=1.0)
    assert lapse.top_height_m(305.0, 300.0) == 0.0  # warmer than the air: on the ground
    assert lapse.top_height_m(150.0, 300.0) == CEILING_M  # colder than the tropopause: at the ceiling
    assert CloudHeights.parse("lapse:5").top_height_m(235.0, 300.0) == pytest.approx(13_000.0, abs=1.0)
    tropical = CloudHeights.parse("tropical")
    heights = tropical.top_height_m(300.0 - np.array([6.0, 12.0, 16.0, 23.0]), 300.0)
    assert np.allclose(heights, [1000, 2000, 3000, 4000], atol=1.0)
    assert np.ptp(np.diff(heights)) == 0.0
    assert tropical.top_height_m(298.0, 300.0) == pytest.approx(333.3, 0.01)
    # not linear: 4 K per km between 2 and 3 km, 7 between 3 and 4
    assert tropical.top_height_m(286.0, 300.0) == pytest.approx(2500.0, abs=1.0)
    assert CloudHeights.parse("ground").top_height_m(200.0, 300.0) == 0.0
    assert str(lapse) == "lapse:6.5" and str(tropical) == "tropical"


@pytest.mark.parametrize("text", ["lapse", "lapse:0", "lapse:-3", "lapse:x", "tropical:2", "steep", ""])
def test_a_law_it_does_not_know_is_named(text):
    with pytest.raises(DataError, match=repr(text).replace("(", r"\(")):
        CloudHeights.parse(text)
    with pytest.raises(DataError):
        SimulationSpec(cloud_heights=text)


@pytest.fixture(scope="module")
def scene():
    return Scene(4, clouds=CloudHeights.parse("lapse:6.5"))


def test_clouds_stand_where_they_are_and_nowhere_else(scene):
    rng = np.random.default_rng(2)
    lat, lon = rng.uniform(-0.4, 0.4, 50_000), rng.uniform(-np.pi, np.pi, 50_000)
    top = scene.top_m(lat, lon)
    flat = Scene(4)
    assert np.all(flat.top_m(lat, lon) == 0.0)
    cloudy = flat.temperature_k(lat, lon) < 275.0  # cold: a cloud covers the point
    clear = np.isclose(flat.temperature_k(lat, lon), 301.0 - 12.0 * np.sin(lat) ** 2, atol=3.5)
    assert np.median(top[cloudy]) > 4000.0 and top.max() <= CEILING_M
    assert np.mean(top[clear] == 0.0) > 0.9
    # the temperature of the scene does not depend on the law: clouds are moved up, not changed
    assert np.array_equal(scene.temperature_k(lat, lon), flat.temperature_k(lat, lon))


def test_rays_meet_the_first_cloud_they_pass(scene):
    rng = np.random.default_rng(3)
    sat = wgs84.geodetic_to_ecef(0.1, 1.0, 833e3)
    ground = wgs84.geodetic_to_ecef(0.1 + rng.uniform(-0.2, 0.2, 4000), 1.0 + rng.uniform(-0.2, 0.2, 4000))
    los = (ground - sat) / np.linalg.norm(ground - sat, axis=1, keepdims=True)
    t, lat, lon, h = scene.intersect(sat, los)
    assert np.allclose(wgs84.geodetic_to_ecef(lat, lon, h), sat + t[:, None] * los, atol=0.05)  # on the ray
    assert np.abs(h - scene.top_m(lat, lon)).max() < 1.0  # on the surface
    assert (h > 3000).mean() > 0.2  # many rays end on a cloud
    # the first: every point of the ray before it, 20 m apart, is above the surface, but for grazes of a
    # cloud's corner shorter than the march's step (500 m of ground), a few tens of metres deep
    before = t[:, None] - np.arange(20.0, 40_000.0, 20.0)[None, :]
    points = sat + before[..., None] * los[:, None, :]
    plat, plon, ph = wgs84.ecef_to_geodetic(points)
    under = np.where(ph < CEILING_M, scene.top_m(plat, plon) - ph, 0.0)
    grazed = (under > 1.0).any(axis=1)
    assert grazed.mean() < 0.005 and under.max() < 100.0 and (under > 1.0).sum(axis=1).max() * 20 < 500
    # without clouds the ray meets the ground (the ellipsoid here), as GEO reports
    t0, _, _, h0 = scene.intersect(sat, los, clouds=False)
    assert np.allclose(t0, wgs84.intersect_ellipsoid(sat, los), atol=0.05) and np.abs(h0).max() < 0.01
    assert np.all(t <= t0 + 0.05)


def test_the_rows_can_be_turned_where_geo_does_not_see():
    plain = Simulator(SimulationSpec(granules=1, profile="zero"))
    turned = Simulator(SimulationSpec(granules=1, profile="zero", fov_rows_alpha_urad=300.0))
    alpha = [np.arctan2(s.los_true[..., 0], s.los_true[..., 2]) for s in (plain, turned)]
    moved = (alpha[1] - alpha[0]) / 1e-6  # (FOR, FOV) urad
    assert np.allclose(moved[:, 6:9], 150.0, atol=1e-3) and np.allclose(moved[:, 0:3], -150.0, atol=1e-3)
    assert np.allclose(moved[:, 3:6], 0.0, atol=1e-6)
    assert np.array_equal(plain.los_geo, turned.los_geo)  # GEO does not know
    assert np.allclose(ins.cris_los_sbf(), plain.los_true)


def test_sharp_edges_cut_the_cover_where_soft_ones_fade_it():
    # 100 km along a parallel, 250 m apart, across the edges of a few clouds
    lat = np.full(400, 0.1)
    lon = 0.3 + np.arange(400) * 250.0 / 6.371e6
    soft, sharp = Scene(4), Scene(4, edges="sharp")
    ground = Scene(4, cloud_fraction=0.0).temperature_k(lat, lon)  # no cloud anywhere
    top = np.minimum(scene_module._top_k(soft.surface(scene_module._unit_vectors(lat, lon))[..., 0]), ground)
    cover = {s.edge: (ground - s.temperature_k(lat, lon)) / (ground - top) for s in (soft, sharp)}
    partial = {edge: np.mean((c > 0.01) & (c < 0.99)) for edge, c in cover.items()}
    assert partial[soft.edge] > 0.2 and partial[sharp.edge] < partial[soft.edge] / 10
    clear = cover[soft.edge] < 1e-6  # the same clouds: where the soft cover is none, so is the sharp
    assert clear.mean() > 0.2 and np.all(cover[sharp.edge][clear] < 1e-6)
    with pytest.raises(DataError, match="'crisp'"):
        SimulationSpec(cloud_edges="crisp")


def test_the_wind_carries_the_clouds_and_leaves_the_ground():
    # along the equator of a scene of sea, a wind about the z axis carries the clouds east
    still = Scene(4, land_fraction=0.0, clouds=CloudHeights.parse("lapse:6.5"), edges="sharp")
    windy = Scene(
        4, land_fraction=0.0, clouds=still.clouds, edges="sharp", wind=Wind((0.0, 0.0, 1.0), 30.0, 0.0)
    )
    lat = np.zeros(4000)
    lon = 0.3 + np.arange(4000) * 100.0 / 6.371e6  # 400 km, 100 m apart
    moved_rad = 30.0 * 100.0 / 6.371e6  # 3 km in 100 s
    assert np.allclose(windy.top_m(lat, lon + moved_rad, 100.0), still.top_m(lat, lon), atol=0.5)
    assert np.allclose(windy.temperature_k(lat, lon + moved_rad, unix_s=100.0), still.temperature_k(lat, lon))
    assert np.array_equal(windy.top_m(lat, lon, 0.0), still.top_m(lat, lon))  # at the reference time
    cloudy = still.top_m(lat, lon) > 3000.0
    moved = np.abs(windy.top_m(lat, lon, 100.0) - still.top_m(lat, lon)) > 1000.0  # an edge passed
    assert 0.1 < cloudy.mean() < 0.9 and moved.mean() > 0.02
    # the ground stays: without its clouds the scene is the same at every time
    assert np.array_equal(
        windy.temperature_k(lat, lon, unix_s=100.0, cloudy=False), still.temperature_k(lat, lon, cloudy=False)
    )
    # a ray at a time meets the clouds where the wind has them then
    sat = wgs84.geodetic_to_ecef(0.0, 0.4, 833e3)
    ground = wgs84.geodetic_to_ecef(np.zeros(2000), 0.4 + np.linspace(-0.05, 0.05, 2000))
    los = (ground - sat) / np.linalg.norm(ground - sat, axis=1, keepdims=True)
    _, lat_hit, lon_hit, h = windy.intersect(sat, los, unix_s=100.0)
    assert np.abs(h - windy.top_m(lat_hit, lon_hit, 100.0)).max() < 1.0 and (h > 3000).mean() > 0.1
    assert np.abs(h - still.top_m(lat_hit, lon_hit)).max() > 1000.0


def test_the_case_wind_blows_along_the_track():
    sim = Simulator(SimulationSpec(granules=1, profile="zero", wind_in_track_m_s=20.0))
    r, v = sim.orbit.state_ecef(sim.t0)
    axis = np.array(sim.scene.wind.axis)
    assert abs(axis @ r) < 1e-9 * np.linalg.norm(r) and abs(axis @ v) < 1e-9 * np.linalg.norm(v)
    c, s = sim.scene.wind.turn_back(sim.t0 + 100.0)  # 2 km in 100 s, turned back: against the flight
    back = scene_module._turned(*(r / np.linalg.norm(r)), axis, c, s)
    assert np.dot(
        np.array(back) * 6.371e6 - r / np.linalg.norm(r) * 6.371e6, v / np.linalg.norm(v)
    ) == pytest.approx(-2000.0, rel=1e-3)
    for wrong in ({"wind_in_track_m_s": float("nan")}, {"cloud_emissivity": 0.0}, {"cloud_emissivity": 1.2}):
        with pytest.raises(DataError, match=repr(next(iter(wrong.values())))):
            SimulationSpec(**wrong)


def test_thin_clouds_let_the_ground_behind_them_show():
    opaque = Simulator(
        SimulationSpec(granules=1, profile="zero", cloud_heights="lapse:6.5", cloud_edges="sharp")
    )
    thin = Simulator(
        SimulationSpec(
            granules=1, profile="zero", cloud_heights="lapse:6.5", cloud_edges="sharp", cloud_emissivity=0.4
        )
    )
    r, _ = opaque.orbit.state_ecef(opaque.t0)
    lat0, lon0, _ = wgs84.ecef_to_geodetic(r)
    rng = np.random.default_rng(5)
    ground = wgs84.geodetic_to_ecef(
        lat0 + rng.uniform(-0.05, 0.05, 3000), lon0 + rng.uniform(-0.05, 0.05, 3000)
    )
    los = (ground - r) / np.linalg.norm(ground - r, axis=1, keepdims=True)
    (t_cloud,), (w,) = opaque.seen(r, los, opaque.t0)
    assert np.all(w == 1.0)
    temps, weights = thin.seen(r, los, thin.t0)
    assert np.array_equal(temps[0], t_cloud) and np.allclose(weights.sum(axis=0), 1.0)
    hit_m = thin.met(r, los, thin.t0, thin.surface(r, los))[2]
    high = hit_m > CIRRUS_BASE_M  # cirrus: thin; the clouds below stay opaque
    assert 0.1 < high.mean() < 0.9 and 0.05 < np.mean((hit_m > 1000) & ~high)
    assert np.all(weights[0][high] == 0.4) and np.all(weights[0][~high] == 1.0)
    assert (
        np.mean(temps[1] == t_cloud) > 0.2
    )  # where a ray meets no cloud, it sees the same ground either way
    # a thin cloud's brightness temperature lies between its top's and the ground's: it reads too low
    band_k = [thin.band.bt_from_radiance(np.interp(t, sim_module.T_BINS_K, thin.band_table)) for t in temps]
    radiance = sum(
        w * np.interp(t, sim_module.T_BINS_K, thin.band_table) for t, w in zip(temps, weights, strict=True)
    )
    mixed_k = thin.band.bt_from_radiance(radiance)
    assert np.all((mixed_k[high] > band_k[0][high] + 2.0) & (mixed_k[high] < band_k[1][high]))
    assert np.allclose(mixed_k[~high], band_k[0][~high], atol=1e-3)


def test_a_laws_lift_is_what_the_band_sees_of_the_simulators_own_tops():
    """law_m_per_k, measured from the law and the band alone, against the tops the simulator's rays meet:
    their heights over how much colder than the clear sea below them the band sees them."""
    sim = Simulator(
        SimulationSpec(granules=1, profile="zero", cloud_heights="lapse:6.5", cloud_edges="sharp", seed=3)
    )
    r, _ = sim.orbit.state_ecef(sim.t0)
    lat0, lon0, _ = wgs84.ecef_to_geodetic(r)
    rng = np.random.default_rng(8)
    ground = wgs84.geodetic_to_ecef(lat0 + rng.uniform(-0.1, 0.1, 4000), lon0 + rng.uniform(-0.1, 0.1, 4000))
    los = (ground - r) / np.linalg.norm(ground - r, axis=1, keepdims=True)
    surface = sim.surface(r, los)
    (seen_k,), _ = sim.seen(r, los, sim.t0, surface)
    hit_m = sim.met(r, los, sim.t0, surface)[2]
    clear_k = sim.scene.temperature_k(*surface, cloudy=False)
    band = [
        sim.band.bt_from_radiance(np.interp(t, sim_module.T_BINS_K, sim.band_table))
        for t in (clear_k, seen_k)
    ]
    top = hit_m > 2000.0
    assert top.sum() > 200
    cooling_k = (band[0] - band[1])[top]
    measured = np.sum(hit_m[top] * cooling_k) / np.sum(cooling_k**2)
    law = sim_module.law_m_per_k("j01", "lapse:6.5")
    assert law == pytest.approx(measured, rel=0.03)
    assert law > 1.15 * 1000 / 6.5  # the window shrinks the BT contrast: not 1000 / G
    assert sim_module.law_m_per_k("j01", "lapse:5.2") / sim_module.law_m_per_k("j01", "lapse:7.8") == (
        pytest.approx(1.5, rel=1e-3)
    )
    assert sim_module.law_m_per_k("j01", "ground") is None
