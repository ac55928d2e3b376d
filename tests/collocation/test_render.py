"""What each CrIS FOV row sees of a granule whose pixels stand at a height: the sweep against a brute-force
ray march through the column the pixels were drawn from, and each ray at its own place across the track."""

import numpy as np
import pytest

from monitor.collocation.render import Met, render_height_field, rendered_bt, rendered_met, swept_bt
from monitor.collocation.views import Across, view_tangents
from tests.collocation.test_lift import scan_geometry

M_PER_K = 150.0
PIXEL_M = 375.0
FOV_PX = 37  # a CrIS FOV's 14 km along the track


class Column:
    """One VIIRS column's slanted plane (x along the track, z up, m): a dozen opaque clouds 1-8 km wide and
    2-12 km high standing on the ground, their tops falling to the ground over 1.5 km shoulders, tops and
    sides at the law's temperature (300 K minus height over M_PER_K), over ground whose BT varies by 1 K
    (so that hidden ground matters)."""

    def __init__(self, rng, n=12, length_m=150e3, shoulder_m=1500.0):
        self.centre_m, self.width_m = rng.uniform(0, length_m, n), rng.uniform(1e3, 8e3, n)
        self.top_m, self.shoulder_m = rng.uniform(2e3, 12e3, n), shoulder_m

    def height(self, x):
        """The height (m) at x."""
        out = np.abs(np.asarray(x)[..., None] - self.centre_m) - self.width_m / 2  # > 0 off the plateaus
        fall = 0.5 + 0.5 * np.cos(np.pi * np.clip(out / self.shoulder_m, 0.0, 1.0))
        return np.max(fall * self.top_m, axis=-1)

    def seen(self, x, tan, dz=5.0):
        """The BT (K) the rays from ground points x climbing *tan* m per m of height meet first: marched down
        in steps of dz from 12.5 km."""
        met = np.zeros(np.shape(x))
        done = np.zeros(np.shape(x), bool)
        for z in np.arange(12.5e3, 0.0, -dz):
            hit = ~done & (self.height(x + z * tan) >= z)
            met[hit], done = z, done | hit
        return 300.0 - met / M_PER_K - np.where(done, 0.0, 1.0 - np.sin(x / 700.0))

    def pixels(self, x, tan, n=9):
        """The BT (K) of pixels PIXEL_M long about x, seen along *tan*: the mean of n rays across each."""
        sub = (np.arange(n) - n // 2) / n * PIXEL_M
        return self.seen(x[:, None] + sub, np.asarray(tan)[:, None] + 0.0 * sub).mean(axis=1)


def _fov_rms(err):
    """The RMS over every FOV_PX pixels along the track of the mean of *err*: what a CrIS cone sees of it."""
    return np.sqrt(np.mean(np.convolve(err, np.ones(FOV_PX) / FOV_PX, mode="valid") ** 2))


@pytest.mark.parametrize("seed", [7, 8])
def test_the_sweep_gives_what_each_row_sees_at_a_fovs_scale(seed):
    """From the BT VIIRS saw (its rays within 7 mrad of the scan plane; each pixel the mean over its
    length) and the heights the law gives them, the rows behind and ahead (21.6 mrad at the ground) see
    what a brute-force march through the column meets with at most half the pixels' own BT's RMS error
    (which misses by > 1 K), and less than it over a FOV's length (measured: 15-80 % less over 37 pixels,
    50-85 % over 19, with a warm bias of 0.05-0.1 K, seeds 7-10); VIIRS's own view is its BT."""
    column = Column(np.random.default_rng(seed))
    rows = 400
    x = PIXEL_M * np.arange(float(rows))
    b = 7e-3 * np.sin(np.arange(float(rows)) * 0.37)
    bt = column.pixels(x, b)
    height = M_PER_K * np.maximum(300.0 - bt, 0.0)
    views = np.array([-0.0216, 0.0216])
    column_of = [v[:, None] for v in (x, b, height, bt)]
    seen = render_height_field(
        *column_of[:2], *column_of[2:], np.broadcast_to(views[:, None, None], (2, rows, 1)), M_PER_K
    )
    assert seen.dtype == np.float32 and seen.shape == (2, rows, 1)
    own = render_height_field(*column_of, b[None, :, None], M_PER_K)[0, :, 0]
    assert np.mean(own == bt.astype(np.float32)) >= 0.95
    inner = slice(40, -40)  # rays that stay over the column
    for j, view in enumerate(views):
        truth = column.pixels(x, np.full(rows, view))
        geo, rendered = (bt - truth)[inner], (seen[j, :, 0] - truth)[inner]
        assert np.sqrt(np.mean(geo**2)) > 1.0, view
        assert np.sqrt(np.mean(rendered**2)) <= 0.5 * np.sqrt(np.mean(geo**2)), view
        assert _fov_rms(rendered) < _fov_rms(geo), view


def test_flat_ground_is_left_as_it_is():
    """No height: every view sees each pixel's own BT."""
    rng = np.random.default_rng(4)
    x = PIXEL_M * np.arange(64)[:, None] + rng.normal(0, 20, (64, 8))
    bt = rng.uniform(250.0, 300.0, x.shape)
    a = np.broadcast_to(np.array([-0.04, 0.0, 0.04])[:, None, None], (3, *x.shape))
    seen = render_height_field(x, np.zeros(x.shape), np.zeros(x.shape), bt, a, M_PER_K)
    assert np.all(seen == bt.astype(np.float32))


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


def test_only_the_pixels_asked_for_are_rendered():
    """The columns a swath piece keeps are rendered as in the whole granule (each column's sweep is its
    own; only the scan's SBF axis, fitted on the rendered columns' ends, moves by a hair), the rest NaN."""
    lat, lon, h, _, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    bt = np.full(lat.shape, 295.0, np.float32)
    bt[10:21] = 230.0
    alphas = np.array([-0.0191, 0.0, 0.0191])
    whole = rendered_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K)
    part = rendered_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K, columns=slice(100, 300))
    assert np.all(np.isnan(part[:, :, :100])) and np.all(np.isnan(part[:, :, 300:]))
    np.testing.assert_allclose(part[:, :, 100:300], whole[:, :, 100:300], atol=0.01)
    no_scan = rendered_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K, scans=slice(1, 1))
    assert np.all(np.isnan(no_scan))


def _every_stretch(x, b, h, bt, a, m_per_k):
    """The sweep of one column (the module docstring's three steps) with every stretch tested for every
    ray: no reach."""
    idx = np.flatnonzero(np.isfinite(x))
    hit = x[idx] + h[idx] * b[idx]
    order = np.argsort(hit, kind="stable")
    ps, rs = hit[order], idx[order]
    edges = np.concatenate([[-np.inf], 0.5 * (ps[1:] + ps[:-1]), [np.inf]])
    out = np.full(a.shape, np.nan)
    for v in range(a.shape[0]):
        for r0 in idx:
            s0, av = x[r0], a[v, r0]
            z1, z2 = (edges[:-1] - s0) / av, (edges[1:] - s0) / av
            z = np.minimum(h[rs], np.maximum(z1, z2))
            z[z < np.maximum(np.minimum(z1, z2), 0.0)] = -1.0
            best = int(np.argmax(z))
            if z[best] < 0:
                continue
            top = h[rs[best]]
            if top - z[best] > 1.0:
                out[v, r0] = bt[rs[best]] + (top - z[best]) / m_per_k
                continue
            at = s0 + z[best] * av
            k = int(np.searchsorted(ps, at)) - 1
            if not 0 <= k < len(ps) - 1:  # beyond the column's first or last hit: that pixel's
                out[v, r0] = bt[rs[best]]
                continue
            w = (at - ps[k]) / (ps[k + 1] - ps[k])
            out[v, r0] = (1 - w) * bt[rs[k]] + w * bt[rs[k + 1]]
    return out


@pytest.mark.parametrize("steep", [0.05, 0.6])
def test_a_rays_reach_leaves_out_no_stretch_it_could_meet(steep):
    """The sweep tests only the stretches within a ray's reach, bounded by the pixels near its foot (and
    by the column's highest beyond them): it renders what testing every stretch renders, for CrIS's
    tangents (0.05) and for rays so slanted (0.6) that the reach passes the near pixels' bound."""
    rng = np.random.default_rng(11)
    n = 240
    x = PIXEL_M * np.arange(n) + rng.normal(0, 30, n)
    h = np.where(rng.random(n) < 0.3, rng.uniform(0, 12e3, n), 0.0)
    h[n // 2] = 15e3  # one tower whose run at the steep tangent is ~24 pixels
    b = rng.uniform(-0.01, 0.01, n)
    bt = 290.0 - h / M_PER_K + rng.normal(0, 0.5, n)
    a = np.stack([np.full(n, -steep), np.full(n, steep)])
    got = render_height_field(x[:, None], b[:, None], h[:, None], bt[:, None], a[:, :, None], M_PER_K)
    np.testing.assert_allclose(got[..., 0], _every_stretch(x, b, h, bt, a, M_PER_K), rtol=0, atol=1e-4)


def _deck(rows=12, cols=10, height_m=10e3, shift_m=None):
    """A flat grid under an opaque deck *height_m* high: GEO points 375 m apart along the track (x) and
    across it (y, the columns' way), each row shifted across by *shift_m* (rows,); the BT rises 0.5 K per
    column's width across the track, so a value taken a fraction of a column aside reads half that."""
    shift = np.zeros(rows) if shift_m is None else shift_m
    r, c = np.meshgrid(np.arange(rows), np.arange(cols), indexing="ij")
    geo = np.stack([r * PIXEL_M, c * PIXEL_M + shift[:, None], np.zeros(r.shape)], -1).astype(float)
    unit = np.broadcast_to([0.0, 1.0, 0.0], geo.shape).copy()
    bt = 250.0 + 0.5 * geo[..., 1] / PIXEL_M
    return geo, unit, bt, np.full(r.shape, height_m)


def test_a_ray_takes_its_value_at_its_own_place_across_the_track():
    """Under a deck 10 km high, a CrIS ray tilted 0.01 more across the track than VIIRS's meets it 100 m
    (0.27 columns) aside: it reads the BT there, between its column and the next on that side; at the
    grid's last column, with no neighbour, the pixel's own. Without the cross-track data, its own."""
    geo, unit, bt, height = _deck()
    rows, cols = bt.shape
    x, b = geo[..., 0], np.zeros(bt.shape)
    a = np.zeros((2, rows, cols))  # both views climb straight up in-track: each ray meets its own top
    tilt = np.array([0.01, -0.01])
    across = Across(geo, unit, np.zeros(bt.shape), np.broadcast_to(tilt[:, None, None], a.shape).copy())
    seen = render_height_field(x, b, height, bt, a, M_PER_K, across)
    inner = slice(1, cols - 1)
    np.testing.assert_allclose(
        seen[:, 2:-2, inner], (bt + 0.5 * tilt[:, None, None] * 10e3 / PIXEL_M)[:, 2:-2, inner], atol=1e-4
    )
    assert np.allclose(seen[0, 2:-2, -1], bt[2:-2, -1]) and np.allclose(seen[1, 2:-2, 0], bt[2:-2, 0])
    plain = render_height_field(x, b, height, bt, a, M_PER_K)
    assert np.allclose(plain[:, 2:-2], bt[2:-2].astype(np.float32))


def test_a_top_met_in_another_row_is_read_at_the_rays_own_place_across():
    """Rows shifted across the track by up to 150 m (pixels of other scans and detectors at one column
    index): a ray climbing 375 m ahead per 10 km meets the next row's top, and reads it where the ray is,
    at its own row's place across the track, not the next row's."""
    shift = np.random.default_rng(3).uniform(-150.0, 150.0, 12)
    geo, unit, bt, height = _deck(shift_m=shift)
    rows, cols = bt.shape
    a = np.full((1, rows, cols), PIXEL_M / 10e3)
    across = Across(geo, unit, np.zeros(bt.shape), np.zeros(a.shape))
    seen = render_height_field(geo[..., 0], np.zeros(bt.shape), height, bt, a, M_PER_K, across)[0]
    plain = render_height_field(geo[..., 0], np.zeros(bt.shape), height, bt, a, M_PER_K)[0]
    inner = (slice(2, rows - 2), slice(1, cols - 1))
    np.testing.assert_allclose(seen[inner], bt[inner], atol=1e-3)  # the ray's own place across
    np.testing.assert_allclose(plain[inner], np.roll(bt, -1, axis=0)[inner], atol=1e-3)  # the next row's


def test_a_top_met_in_another_scan_two_columns_aside_is_read_at_the_rays_own_place():
    """Rows alternately 1.8 columns across the track from each other (one column index of two scans where
    they overlap: the Earth turns ~2 columns under the track between them): a ray that meets the next
    row's top reads it between that row's columns about its own place, on either side, not a column
    short of it."""
    shift = np.where(np.arange(12) % 2 == 1, 1.8 * PIXEL_M, 0.0)
    geo, unit, bt, height = _deck(shift_m=shift)
    rows, cols = bt.shape
    a = np.full((1, rows, cols), PIXEL_M / 10e3)
    across = Across(geo, unit, np.zeros(bt.shape), np.zeros(a.shape))
    seen = render_height_field(geo[..., 0], np.zeros(bt.shape), height, bt, a, M_PER_K, across)[0]
    inner = (slice(2, rows - 2), slice(2, cols - 2))
    np.testing.assert_allclose(seen[inner], bt[inner], atol=1e-3)


def test_across_the_track_flat_scenes_and_parts_render_as_before():
    """With the cross-track position taken: a flat scene is left as it is; a part renders as in the whole
    (its edge columns drawn with their neighbours)."""
    lat, lon, h, _, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    alphas = np.array([-0.0191, 0.0, 0.0191])
    flat = rendered_bt(lat, lon, h, np.full(lat.shape, 280.0, np.float32), good, sat[None], v[None], alphas,
                       M_PER_K)  # fmt: skip
    assert np.all(flat == 280.0)
    bt = np.full(lat.shape, 295.0, np.float32)
    bt[10:21] = 230.0 + 20.0 * (np.arange(lat.shape[1]) % 2)  # the band's BT alternates across the track
    whole = rendered_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K)
    part = rendered_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K, columns=slice(100, 300))
    assert np.all(np.isnan(part[:, :, :100])) and np.all(np.isnan(part[:, :, 300:]))
    np.testing.assert_allclose(part[:, :, 100:300], whole[:, :, 100:300], atol=0.01)
    plain = swept_bt(lat, lon, h, bt, good, sat[None], v[None], alphas, M_PER_K)
    assert np.nanmax(np.abs(whole - plain)) > 0.01  # the cross-track position moves some rays' values


def test_what_each_ray_met_is_told():
    """Under a deck 10 km high, rays climbing 375 m ahead per 10 km meet the next row's top: of their own
    scan, or of the next scan for a scan's last row. Over flat ground with one pixel standing 10 km high,
    the ray one row behind it meets its wall halfway up (5 km, the wall's BT the top's plus 5 km of air),
    the others their own pixel; what is told does not change what is rendered."""
    geo, unit, bt, height = _deck(rows=40, cols=4)
    a = np.full((1, *bt.shape), PIXEL_M / 10e3)
    met = np.empty(a.shape, np.uint8)
    args = (geo[..., 0], np.zeros(bt.shape), height, bt, a, M_PER_K)
    seen = render_height_field(*args, met=met)
    np.testing.assert_array_equal(seen, render_height_field(*args))
    assert np.all(met[0, 1:31] == Met.SCAN_TOP) and np.all(met[0, 31] == Met.OTHER_SCAN_TOP)
    assert np.all(met[0, 32:39] == Met.SCAN_TOP)
    tower = np.zeros(bt.shape)
    tower[20] = 10e3
    bt = np.where(tower > 0, 300.0 - 10e3 / M_PER_K, 300.0)
    seen = render_height_field(geo[..., 0], np.zeros(bt.shape), tower, bt, a, M_PER_K, met=met)
    assert np.all(met[0, 20] == Met.WALL) and np.all(met[0, 19] == Met.SCAN_TOP)
    assert np.all(met[0, 1:19] == Met.OWN_TOP) and np.all(met[0, 21:39] == Met.OWN_TOP)
    np.testing.assert_allclose(seen[0, 20], 300.0 - 5e3 / M_PER_K, atol=1e-3)


def test_a_granule_tells_what_its_rays_met():
    """Through :func:`rendered_met`: every rendered ray is told, the rest NOTHING; a flat granule's rays all
    meet their own pixel, and a cloud band's edge shows the rows ahead and behind its walls."""
    lat, lon, h, _, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    alphas = np.array([-0.0191, 0.0, 0.0191])
    flat = np.full(lat.shape, 280.0, np.float32)
    orbit = (sat[None], v[None], alphas, M_PER_K)
    _, met = rendered_met(lat, lon, h, flat, good, *orbit, columns=slice(100, 300))
    assert np.all(met[:, :, 100:300] == Met.OWN_TOP) and np.all(met[:, :, :100] == Met.NOTHING)
    bt = np.full(lat.shape, 295.0, np.float32)
    bt[10:21] = 230.0
    seen, met = rendered_met(lat, lon, h, bt, good, *orbit)
    np.testing.assert_array_equal(seen, rendered_bt(lat, lon, h, bt, good, *orbit))
    assert np.any(met[0] == Met.WALL) and np.any(met[2] == Met.WALL) and not np.any(met[1] == Met.WALL)
