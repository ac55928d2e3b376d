"""Where the rays to each GEO point lie: the view tangents, in-track and across the track, against the lines
of sight of a scan drawn for the test."""

import numpy as np
import pytest

from monitor.collocation.views import TANGENT_STEP, view_tangents, view_tangents_across
from monitor.geometry import wgs84
from tests.collocation.test_lift import scan_geometry


def test_the_view_tangents_follow_the_lines_of_sight():
    """b is the along-track run per metre of height up a pixel's VIIRS line of sight (the spacecraft at the
    pixel's time); a CrIS row at a detector's own in-track angle sees that pixel along VIIRS's line
    (a = b); an outer row's 19.1 mrad are ~21.6 mrad at the ground at nadir (1 + range / R_earth),
    towards -x for the row ahead."""
    lat, lon, h, origin, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    c, i = 200, 3  # a column near nadir, a detector near the scan's edge
    own = np.arctan(np.tan((i - 15.5) * 4.5e-4) / np.cos(np.linspace(-0.9, 0.9, 400)[c]))
    alphas = np.array([own, 0.0191, -0.0191])
    first = TANGENT_STEP - c % TANGENT_STEP  # c is then a column where the views are traced
    x, b, a = view_tangents(lat, lon, h, good, sat[None], v[None], alphas, first_column=first)
    assert a[0, i, c] == pytest.approx(b[i, c], abs=1e-6)
    # between traced columns they are interpolated in scan angle (this scan's columns are 4.5 mrad apart,
    # 16 times VIIRS's, so the bend between two traced ones is ~250 times a real scan's)
    between = view_tangents(lat, lon, h, good, sat[None], v[None], alphas)[2]
    assert c % TANGENT_STEP and np.abs(between[:, :, c] - a[:, :, c]).max() < 1e-5
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


def test_the_cross_track_tangents_follow_the_lines_of_sight():
    """The across direction is horizontal and square to the column's way; VIIRS's cross-track tangent is
    the run along it per metre of height up its line of sight; a CrIS row at a detector's own in-track
    angle sees that pixel along VIIRS's line, across the track too; the in-track results are
    :func:`view_tangents`'s."""
    lat, lon, h, origin, sat, v = scan_geometry()
    good = np.ones(lat.shape, bool)
    c, i = 200, 3
    own = np.arctan(np.tan((i - 15.5) * 4.5e-4) / np.cos(np.linspace(-0.9, 0.9, 400)[c]))
    alphas = np.array([own, 0.0191, -0.0191])
    first = TANGENT_STEP - c % TANGENT_STEP
    x, b, a, across = view_tangents_across(lat, lon, h, good, sat[None], v[None], alphas, first_column=first)
    plain = view_tangents(lat, lon, h, good, sat[None], v[None], alphas, first)
    for mine, theirs in zip((x, b, a), plain, strict=True):
        np.testing.assert_array_equal(mine, theirs)
    ground = wgs84.geodetic_to_ecef(lat, lon, h)
    np.testing.assert_allclose(across.geo_m, ground, atol=1e-6)
    up = wgs84.geodetic_up(ground)
    assert np.abs(np.sum(across.unit * up, -1)).max() < 1e-9
    look = origin - ground
    run = np.sum(look * across.unit, -1) / np.sum(look * up, -1)
    assert np.abs(run - across.viirs_tan).max() < 1e-5
    assert across.cris_tan[0, i, c] == pytest.approx(across.viirs_tan[i, c], abs=1e-6)


def test_what_is_not_traced_is_nan_in_every_output():
    """Unusable pixels, a scan without its spacecraft position and the rows of a part scan get no tangent:
    NaN in every output, whatever the arrays held before; the usable pixels of the scan with an orbit are
    traced as when it is alone."""
    lat, lon, h, _, sat, v = scan_geometry(cols=64)
    good = np.ones(lat.shape, bool)
    good[5, 10:20] = False
    two = [np.concatenate([f, f]) for f in (lat, lon, h)]
    rows = len(lat)
    part = [np.concatenate([f, f[:7]]) for f in two]  # two scans and 7 rows of a third
    usable = np.concatenate([good, good, good[:7]])
    orbit = np.stack([sat, np.full(3, np.nan)]), np.stack([v, v])  # the second scan has no position
    alphas = np.array([0.0191, -0.0191])
    x, b, a, across = view_tangents_across(*part, usable, *orbit, alphas)
    alone = view_tangents_across(lat, lon, h, good, sat[None], v[None], alphas)
    for mine, theirs in zip((x, b, a), alone[:3], strict=True):
        np.testing.assert_array_equal(mine[..., :rows, :], theirs)
    fields = (x, b, a[0], a[1], across.geo_m, across.unit, across.viirs_tan, across.cris_tan[0])
    for f in fields:
        assert np.isnan(f[5, 10:20]).all() and np.isfinite(f[5, :10]).all()
        assert np.isnan(f[rows:]).all()  # the scan without position and the part scan
