"""What each CrIS FOV row sees of a granule whose pixels stand at a height, against a brute-force ray
march through the scene the pixels were drawn from."""

import numpy as np
import pytest

from monitor.collocation.render import render_height_field, rendered_bt, view_tangents
from monitor.geometry import wgs84
from tests.collocation.test_lift import scan_geometry

M_PER_K = 150.0
PIXEL_M = 375.0


class Blocks:
    """A scene of opaque flat-topped clouds standing on the ground, 2-8 pixels wide and 2-12 km high, their
    edges halfway between pixel centres, their tops and sides at the law's temperature (300 K minus height
    over M_PER_K), over ground whose BT varies (so that hidden ground matters), on a flat Earth: x along
    the track, y across, m."""

    def __init__(self, rng, n=60, size=200):
        self.h = np.zeros((size, size))
        for _ in range(n):
            i, j = rng.integers(0, size - 8, 2)
            self.h[i : i + rng.integers(2, 8), j : j + rng.integers(2, 8)] = rng.uniform(2e3, 12e3)

    def height(self, x, y):
        """The scene's height (m) at (x, y); 0 off its grid."""
        i, j = (np.floor(v / PIXEL_M + 0.5).astype(int) for v in (x, y))
        inside = (i >= 0) & (j >= 0) & (i < self.h.shape[0]) & (j < self.h.shape[1])
        n = self.h.shape[0] - 1
        return np.where(inside, self.h[np.clip(i, 0, n), np.clip(j, 0, n)], 0.0)

    def seen(self, x, y, along, across_m, dz=2.0):
        """The BT (K) the rays from ground points (x, y) climbing *along* and *across_m* m per metre of
        height meet first, and the height (m) there: marched down in steps of dz from 12.5 km."""
        ground = 290.0 + 5.0 * np.sin(x / 700.0) * np.cos(y / 900.0)
        met = np.zeros(np.shape(x))
        done = np.zeros(np.shape(x), bool)
        for z in np.arange(12.5e3, 0.0, -dz):
            hit = ~done & (self.height(x + z * along, y + z * across_m) >= z)
            met[hit], done = z, done | hit
        return np.where(done, 300.0 - met / M_PER_K, ground), met


@pytest.mark.parametrize("across_m", [0.0, 0.3, -1.1])  # nadir, 17 degrees, the swath's edge
def test_the_rendering_is_what_a_ray_march_through_the_scene_meets(across_m):
    """From the heights and BT VIIRS saw, the pictures of the rows behind and ahead (21.6 mrad at the
    ground) are what a brute-force march through the scene meets, within 2 K (a wall's height is found
    to a quarter column) at >= 99.5 % of the points, where VIIRS's own BT is more than 5 K off at >= 0.2
    %; and VIIRS's own view is its BT."""
    scene = Blocks(np.random.default_rng(7))
    rows, cols = 96, 112
    x = PIXEL_M * (np.arange(rows)[:, None] + 40) + np.zeros((rows, cols))
    y = PIXEL_M * (np.arange(cols)[None, :] + 60) + np.zeros((rows, cols))
    b = np.zeros((rows, cols))
    across = np.full(x.shape, across_m / PIXEL_M)
    bt, met = scene.seen(x, y, b, across_m)
    views = np.array([-0.0216, 0.0216])
    seen = render_height_field(
        x, b, across, met, bt, np.broadcast_to(views[:, None, None], (2, rows, cols)), M_PER_K
    )
    assert seen.dtype == np.float32 and seen.shape == (2, rows, cols)
    inner = (slice(8, -8), slice(48 if across_m < 0 else 8, -8))  # rays that stay over the granule
    own = np.abs(render_height_field(x, b, across, met, bt, b[None], M_PER_K)[0] - bt)[inner]
    assert np.mean(own <= 0.01) >= 0.85
    # where VIIRS met a side across the track: found to a quarter column (312 m of a ray's height at 0.3)
    assert own.max() <= (0.01 if across_m == 0 else 1.2)
    for j, view in enumerate(views):
        truth, _ = scene.seen(x, y, np.full(x.shape, view), across_m)
        assert np.mean(np.abs(seen[j] - truth)[inner] <= 2.0) >= 0.995, view
        assert np.mean(np.abs(bt - truth)[inner] > 5.0) >= 0.002, view  # the rows see something else


def test_flat_ground_is_left_as_it_is():
    """No height: every view sees each pixel's own BT."""
    rng = np.random.default_rng(4)
    x = PIXEL_M * np.arange(64)[:, None] + rng.normal(0, 20, (64, 8))
    bt = rng.uniform(250.0, 300.0, x.shape)
    a = np.broadcast_to(np.array([-0.04, 0.0, 0.04])[:, None, None], (3, *x.shape))
    seen = render_height_field(
        x, np.zeros(x.shape), np.full(x.shape, 1e-3), np.zeros(x.shape), bt, a, M_PER_K
    )
    assert np.all(seen == bt.astype(np.float32))


def test_the_view_tangents_follow_the_lines_of_sight():
    """b is the along-track run per metre of height up a pixel's VIIRS line of sight (the spacecraft at the
    pixel's time); a CrIS row at a detector's own in-track angle sees that pixel along VIIRS's line
    (a = b); an outer row's 19.1 mrad are ~21.6 mrad at the ground at nadir (1 + range / R_earth),
    towards -x for the row ahead. Across the track both climb towards nadir by the tangent of the view
    zenith: *across* columns per metre of height."""
    lat, lon, h, origin, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    c, i = 200, 3  # a column near nadir, a detector near the scan's edge
    own = np.arctan(np.tan((i - 15.5) * 4.5e-4) / np.cos(np.linspace(-0.9, 0.9, 400)[c]))
    x, b, a, across = view_tangents(lat, lon, h, good, sat[None], v[None], np.array([own, 0.0191, -0.0191]))
    assert a[0, i, c] == pytest.approx(b[i, c], abs=1e-6)
    ground = wgs84.geodetic_to_ecef(lat, lon, h)
    look = origin - ground  # to the spacecraft at each pixel's time, as the test's scan was drawn
    up = wgs84.geodetic_up(ground)
    north = np.array([0.0, 0.0, 1.0]) - up[..., 2:] * up  # the scan plane's normal on the horizontal
    run = np.sum(look * north, axis=-1) / np.linalg.norm(north, axis=-1) / np.sum(look * up, axis=-1)
    assert np.abs(run - b).max() < 1e-6
    turn = (a[1:, :, c] - b[:, c]).mean(axis=1)
    assert turn[0] == pytest.approx(-0.0191 * (1 + 833 / 6378), rel=0.005)
    assert turn[1] == pytest.approx(-turn[0], rel=0.03)
    assert np.all(np.diff(x[:, c]) > 0)  # the detectors in along-track order, 375 m apart
    assert np.median(np.diff(x[:, c])) == pytest.approx(833e3 * 4.5e-4, rel=0.02)
    east = np.array([0.0, 1.0, 0.0]) - up[..., 1:2] * up  # along the scan, towards higher columns
    cross = np.sum(look * east, axis=-1) / np.linalg.norm(east, axis=-1) / np.sum(look * up, axis=-1)
    step = np.gradient(np.sum(ground * [0.0, 1.0, 0.0], axis=-1), axis=1)
    assert across == pytest.approx(cross / step, rel=0.03, abs=1e-7)
    assert across[16, 20] > 1e-4 and across[16, 380] < -1e-4  # towards nadir


def test_a_granule_is_rendered_as_each_row_sees_it():
    """A cloud band 10 km high (65 K colder at 150 m/K) across one scan of a real scan's geometry: the row
    ahead sees it farther ahead than VIIRS put it (its rays meet the top ~210 m farther on, a wall fills
    some of the rest), the row behind farther back, the centre row where VIIRS put it; flat scenes are
    left as they are."""
    lat, lon, h, origin, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    bt = np.full(lat.shape, 295.0, np.float32)
    bt[10:21] = 230.0
    alphas = np.array([-0.0191, 0.0, 0.0191])
    flat = rendered_bt(lat, lon, h, np.full_like(bt, 280.0), good, sat[None], v[None], alphas, M_PER_K)
    assert np.all(flat == 280.0)
    seen = rendered_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K)
    assert seen.shape == (3, *bt.shape) and seen.dtype == np.float32
    x = view_tangents(lat, lon, h, good, sat[None], v[None], alphas)[0]
    cold = 295.0 - seen[:, :, 150:250]  # columns near nadir
    centroid = np.sum(cold * x[None, :, 150:250], axis=(1, 2)) / np.sum(cold, axis=(1, 2))
    band = np.sum((295.0 - bt[:, 150:250]) * x[:, 150:250]) / np.sum(295.0 - bt[:, 150:250])
    behind, centre, ahead = centroid - band
    assert -375.0 < behind < -10.0 and 10.0 < ahead < 375.0 and ahead - behind > 100.0 and abs(centre) < 20.0
