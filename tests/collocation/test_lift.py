"""How high VIIRS pixels stand: the clear-sky reference and the heights; a scan's geometry for the tests of
what is drawn from them."""

import numpy as np
import pytest
from scipy.ndimage import maximum_filter, uniform_filter

from monitor.collocation.lift import REFERENCE_HALF_PX, ROTATION_RAD_S, height_above_m, reference_k
from monitor.core.constants import VIIRS_DETECTORS
from monitor.geometry import wgs84


def cloudy_field(rows=96, cols=300):
    """295 K with a 230 K cloud disc of radius 20 pixels at (48, 150), a soft edge, and noise."""
    r, c = np.mgrid[:rows, :cols]
    dist = np.hypot(r - 48, c - 150)
    cover = np.clip((22 - dist) / 4, 0, 1)
    bt = 295 - 65 * cover + np.random.default_rng(0).normal(0, 0.3, (rows, cols))
    return bt.astype(np.float32), cover


def test_the_reference_is_the_clear_sky_around_and_never_a_bad_pixel():
    bt, cover = cloudy_field()
    good = np.ones(bt.shape, bool)
    good[10, 10] = False
    bt[10, 10] = 400.0  # a hot unusable pixel never sets the reference
    ref = reference_k(bt, good)
    assert np.all(np.abs(ref - 295) < 1.0)  # the cloud is within reach of clear sky everywhere
    uniform = reference_k(np.full((40, 40), 250.0, np.float32), np.ones((40, 40), bool))
    assert np.allclose(uniform, 250.0)
    none = reference_k(bt, np.zeros(bt.shape, bool))
    assert np.all(np.isnan(none))
    # beyond the reach, a wide deck's middle is its own reference: no lift there
    wide = np.full((40, 4 * REFERENCE_HALF_PX), 230.0, np.float32)
    wide[:, :5] = 295.0
    assert reference_k(wide, np.ones(wide.shape, bool))[0, -1] == pytest.approx(230.0)


@pytest.mark.parametrize(
    ("shape", "half_px"), [((96, 300), 100), ((70, 45), 100), ((64, 500), 7), ((5, 3), 1)]
)
def test_the_reference_is_the_warmest_3x3_mean_within_reach_to_the_pixel_edges(shape, half_px):
    """Against the definition written with scipy's filters: the 3 x 3 mean of the usable pixels (the edge
    repeated) where more than half of the nine are usable, then the warmest over the square."""
    rng = np.random.default_rng(sum(shape) + half_px)
    bt = (280 + 20 * rng.standard_normal(shape)).astype(np.float32)
    good = rng.random(shape) > 0.3
    bt[rng.random(shape) < 0.02] = np.nan
    ok = good & np.isfinite(bt)
    count = uniform_filter(ok.astype(np.float64), 3, mode="nearest")
    total = uniform_filter(np.where(ok, bt, 0.0).astype(np.float64), 3, mode="nearest")
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = np.where(count > 0.5, total / count, -np.inf)
    expected = maximum_filter(mean, size=2 * half_px + 1, mode="nearest")
    expected[~np.isfinite(expected)] = np.nan
    got = reference_k(bt, good, half_px)
    assert got.dtype == np.float32
    assert np.array_equal(np.isnan(got), np.isnan(expected))
    assert np.nanmax(np.abs(got - expected)) < 1e-4


def test_a_deck_tens_of_km_wide_stands_at_its_height_in_its_middle():
    """A 60 km deck (160 pixels at 375 m) of 230 K in 295 K clear sky: its middle, 30 km from clear sky,
    takes the clear sky as its reference (within +-40 pixels it took its own 230 K and stood on the
    ground: simulated decks' tops stood kilometres too low, studies/clouds-with-height.md, section 5)."""
    bt = np.full((64, 400), 295.0, np.float32)
    bt[:, 120:280] = 230.0
    ref = reference_k(bt, np.ones(bt.shape, bool))
    assert ref[32, 200] == pytest.approx(295.0)
    assert reference_k(bt, np.ones(bt.shape, bool), 40)[32, 200] == pytest.approx(230.0)


def test_the_height_grows_with_the_cooling_and_is_zero_in_clear_sky():
    bt, cover = cloudy_field()
    good = np.ones(bt.shape, bool)
    ref = reference_k(bt, good)
    lift = height_above_m(bt, good, ref, 150.0)
    assert np.median(lift[cover == 1]) == pytest.approx(150.0 * 65, rel=0.03)
    assert np.percentile(lift[cover == 0], 99) < 150.0 * 1.5  # noise: well under a kilometre
    assert np.all(height_above_m(bt, good, ref, 0.0) == 0) and np.all(
        height_above_m(bt, ~good, ref, 150.0) == 0
    )


def scan_geometry(cols=400):
    """One VIIRS scan (32 detectors) seen from a satellite 833 km over the equator flying north: ground
    points (lat, lon, h) and, per pixel, the spacecraft position at its time (the scan's middle plus the
    velocity times its scan angle over the rotation rate)."""
    sat = wgs84.geodetic_to_ecef(0.0, 0.0, 833e3)
    v = np.array([0.0, 0.0, 7400.0])
    angle = np.linspace(-0.9, 0.9, cols)  # columns in time order
    det = (np.arange(VIIRS_DETECTORS) - 15.5) * 4.5e-4
    pix_sat = sat + v * (angle / ROTATION_RAD_S)[:, None]
    nadir = -sat / np.linalg.norm(sat)
    east = np.array([0.0, 1.0, 0.0])
    north = np.array([0.0, 0.0, 1.0])
    los = (
        np.cos(angle)[None, :, None] * nadir
        + np.sin(angle)[None, :, None] * east
        + np.tan(det)[:, None, None] * north
    )
    los /= np.linalg.norm(los, axis=-1, keepdims=True)
    origin = np.broadcast_to(pix_sat[None], los.shape)
    t = wgs84.intersect_ellipsoid(origin, los)
    lat, lon = wgs84.surface_to_geodetic(origin + t[..., None] * los)
    return lat, lon, np.zeros(lat.shape), origin, sat, v
