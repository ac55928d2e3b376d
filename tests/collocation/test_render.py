"""The rendering of a VIIRS column as a CrIS FOV row sees it, against a ray march through the same columns."""

import numpy as np
import pytest

from monitor.collocation.render import render_columns, rendered_bt, view_tangents
from monitor.geometry import wgs84
from tests.collocation.test_lift import scan_geometry

M_PER_K = 150.0


def _marched(x, w, h, bt, ref, b, a, dz=0.5):
    """What each ray x_i + z a_i meets first, marching down from above the highest top in steps of dz m
    through the columns within 12 pixels: (BT, kind) as render_columns reports them."""
    seen, kind = np.full(len(x), np.nan), np.zeros(len(x), np.int8)
    t = x + h * b
    z = np.r_[np.arange(h.max() + dz, dz / 2, -dz), 0.0][:, None]
    for i in range(len(x)):
        near = np.arange(max(i - 12, 0), min(i + 13, len(x)))
        inside = (np.abs(x[i] + z * a[i] - t[near]) <= w[near] / 2) & (h[near] >= z)  # (z, near)
        k = int(np.argmax(inside.any(axis=1)))  # the first step down that is inside a column
        cand = near[inside[k]]
        j = cand[np.argmin(np.abs(x[i] + h[cand] * a[i] - t[cand]))]
        if z[k, 0] > h[j] - dz:  # met at its top
            seen[i], kind[i] = bt[j], 0 if j == i else 1
        else:
            seen[i], kind[i] = ref[j] - z[k, 0] / M_PER_K, 2
    return seen, kind


def _column(rng, n=400, clouds=16):
    """A column of 375 m pixels with flat-topped clouds of 2-15 km on the ground, at the 6.5 K/km law."""
    x = 375.0 * np.arange(n) + rng.normal(0, 20, n)
    h = np.zeros(n)
    for _ in range(clouds):
        start = rng.integers(5, n - 30)
        h[start : start + rng.integers(2, 25)] = rng.uniform(2e3, 15e3)
    ref = np.full(n, 300.0)
    bt = ref - h / M_PER_K
    b = rng.uniform(-0.007, 0.007, n)  # VIIRS within +-7 mrad of its scan plane
    return x, np.full(n, 375.0), h, bt, ref, b


@pytest.mark.parametrize("view", [-0.0215, 0.0, 0.0215])
def test_the_rendering_is_what_a_ray_march_meets(view):
    """Rows behind, centre, ahead (19.1 mrad, curvature included): the same BT as the march at every
    pixel (walls to the march's 0.5 m step), hidden pixels and walls where the clouds stand."""
    rng = np.random.default_rng(3)
    x, w, h, bt, ref, b = _column(rng)
    a = np.full_like(x, view)
    seen, kind = render_columns(*(v[:, None] for v in (x, w, h, bt, ref, b, a)), M_PER_K)
    march, march_kind = _marched(x, w, h, bt, ref, b, a)
    assert seen[:, 0] == pytest.approx(march, abs=0.5 / M_PER_K + 1e-9)
    assert np.array_equal(kind[:, 0], march_kind)
    if view:
        assert (kind == 2).sum() > 0 and (kind == 1).sum() > 0


def test_flat_ground_and_a_view_along_viirs_leave_every_pixel_its_own():
    """No height, or CrIS looking as VIIRS looked: each GEO point sees its own pixel."""
    rng = np.random.default_rng(4)
    x, w, h, bt, ref, b = _column(rng)
    flat, kind = render_columns(*(v[:, None] for v in (x, w, 0 * h, bt, ref, b, b + 0.02)), M_PER_K)
    assert np.array_equal(flat[:, 0], bt) and not kind.any()
    same, kind = render_columns(*(v[:, None] for v in (x, w, h, bt, ref, b, b)), M_PER_K)
    assert np.array_equal(same[:, 0], bt) and not kind.any()


def test_a_tall_cloud_hides_the_ground_behind_it_and_shows_its_wall():
    """A 10 km cloud over pixels 100-109, VIIRS at nadir, the row's rays climbing 21.5 mrad towards +x:
    the ray meeting the ground at pixel 99 (215 m before the cloud) sees its top, not that ground; the
    ray at pixel 109 passes the top's far edge and meets the wall below it (8.7 km); the rest see ground."""
    n = 200
    x = 375.0 * np.arange(n)
    h = np.zeros(n)
    h[100:110] = 10e3
    ref = np.full(n, 300.0)
    bt = ref - h / M_PER_K
    w, b = np.full(n, 375.0), np.zeros(n)
    seen, kind = render_columns(*(v[:, None] for v in (x, w, h, bt, ref, b, np.full(n, 0.0215))), M_PER_K)
    seen, kind = seen[:, 0], kind[:, 0]
    assert kind[99] == 1 and seen[99] == bt[100]  # pixel 99's ground point sees the cloud's top
    assert kind[109] == 2 and bt[109] < seen[109] < ref[109]  # the far edge: rays pass under the top
    assert seen[109] == pytest.approx(ref[109] - (41062.5 - x[109]) / 0.0215 / M_PER_K)
    assert np.all(kind[110:] == 0) and np.all(kind[:99] == 0) and np.all(kind[100:109] == 1)


def test_the_view_tangents_follow_the_lines_of_sight():
    """b is the along-track run per metre of height up a pixel's VIIRS line of sight (the spacecraft at the
    pixel's time); a CrIS row at a detector's own in-track angle sees that pixel along VIIRS's line
    (a = b); an outer row's 19.1 mrad are ~21.6 mrad at the ground at nadir (1 + range / R_earth),
    towards -x for the row ahead."""
    lat, lon, h, origin, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    c, i = 200, 3  # a column near nadir, a detector near the scan's edge
    own = np.arctan(np.tan((i - 15.5) * 4.5e-4) / np.cos(np.linspace(-0.9, 0.9, 400)[c]))
    x, b, a = view_tangents(lat, lon, h, good, sat[None], v[None], np.array([own, 0.0191, -0.0191]))
    assert a[0, i, c] == pytest.approx(b[i, c], abs=1e-6)
    ground = wgs84.geodetic_to_ecef(lat, lon, h)
    look = origin - ground  # to the spacecraft at each pixel's time, as the test's scan was drawn
    up = wgs84.geodetic_up(ground)
    north = np.array([0.0, 0.0, 1.0]) - up[..., 2:] * up  # the scan plane's normal on the horizontal
    run = np.sum(look * north, axis=-1) / np.linalg.norm(north, axis=-1) / np.sum(look * up, axis=-1)
    assert np.abs(run - b).max() < 1e-6
    ground = (a[1:, :, c] - b[:, c]).mean(axis=1)
    assert ground[0] == pytest.approx(-0.0191 * (1 + 833 / 6378), rel=0.005)
    assert ground[1] == pytest.approx(-ground[0], rel=0.03)
    assert np.all(np.diff(x[:, c]) > 0)  # the detectors in along-track order, 375 m apart
    assert np.median(np.diff(x[:, c])) == pytest.approx(833e3 * 4.5e-4, rel=0.02)


def test_a_granule_is_rendered_as_each_row_sees_it():
    """A cloud band 10 km high (65 K colder at 150 m/K) across one scan: each row's picture is what a ray
    march through each column meets (sorted along the track, the column's detector step as the width);
    the row ahead sees the band farther ahead than VIIRS put it (its rays meet the top ~210 m farther on,
    a wall fills some of the rest), the row behind farther back, the centre row where VIIRS put it; flat
    scenes are left as they are."""
    lat, lon, h, origin, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    bt = np.full(lat.shape, 295.0, np.float32)
    bt[10:21] = 230.0
    alphas = np.array([-0.0191, 0.0, 0.0191])
    flat = rendered_bt(lat, lon, h, np.full_like(bt, 280.0), good, sat[None], v[None], alphas, M_PER_K)
    assert np.all(flat == 280.0)
    seen = rendered_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K)
    assert seen.shape == (3, *bt.shape) and seen.dtype == np.float32
    x, b, a = view_tangents(lat, lon, h, good, sat[None], v[None], alphas)
    height = (295.0 - bt) * M_PER_K
    for c in (20, 200, 390):
        width = np.full(32, np.median(np.diff(x[:, c])))
        for j in range(3):
            march, _ = _marched(
                x[:, c], width, height[:, c], bt[:, c], np.full(32, 295.0), b[:, c], a[j, :, c]
            )
            assert seen[j, :, c] == pytest.approx(march, abs=0.01), (c, j)
    cold = 295.0 - seen[:, :, 150:250]  # columns near nadir
    centroid = np.sum(cold * x[None, :, 150:250], axis=(1, 2)) / np.sum(cold, axis=(1, 2))
    band = np.sum((295.0 - bt[:, 150:250]) * x[:, 150:250]) / np.sum(295.0 - bt[:, 150:250])
    behind, centre, ahead = centroid - band
    assert -375.0 < behind < -10.0 and 10.0 < ahead < 375.0 and ahead - behind > 100.0 and abs(centre) < 20.0
