"""Pixels split into sub-pixels: placed on the geolocation's local slope within their scan, at the finer
grid's centres, continuous across the antimeridian, and never made up where a pixel has no geolocation."""

import numpy as np
import pytest

from monitor.collocation.subpixels import split_field, split_geolocation, split_values
from monitor.core.bands import BANDS, GRIDS
from monitor.geometry import wgs84
from monitor.sdr import read_file
from monitor.sdr.pairing import plan


def _linear(rows, cols, detectors):
    """A field linear in the row within each scan and in the column, with a jump between scans."""
    r, c = np.mgrid[0:rows, 0:cols].astype(float)
    return 0.01 * (r % detectors) + 0.003 * c + 0.5 * (r // detectors)


@pytest.mark.parametrize("n", [2, 3])
def test_a_linear_field_splits_onto_the_sub_pixel_centres(n):
    det = 4
    a = _linear(8, 5, det)
    out = split_field(a, det, n)
    shifts = (np.arange(n) + 0.5) / n - 0.5
    for r in range(8):
        for c in range(5):
            for k, sr in enumerate(shifts):
                for m, sc in enumerate(shifts):
                    expected = 0.01 * (r % det + sr) + 0.003 * (c + sc) + 0.5 * (r // det)
                    assert out[r * n + k, c * n + m] == pytest.approx(expected, abs=1e-12)


def test_a_missing_row_is_not_made_up_and_its_neighbours_lean_on_one_side():
    det = 4
    a = _linear(4, 3, det)
    a[1] = np.nan  # a bow-tie deleted row
    out = split_field(a, det, 2)
    assert np.isnan(out[2:4]).all()
    # rows 0 and 2 have one neighbour left along the track: their slope is the other side's (here none for
    # row 0: the scan's first row and its only neighbour gone), so row 0 keeps no row slope and is NaN
    assert np.isnan(out[0:2]).all()
    r2 = out[4:6]
    assert np.allclose(r2[:, 0], [0.01 * 1.75 - 0.003 * 0.25, 0.01 * 2.25 - 0.003 * 0.25])
    assert np.isfinite(out[4:]).all()


def test_longitude_is_split_the_short_way_round_the_antimeridian():
    det = 2
    lon = np.radians(np.array([[179.8, 179.95, -179.9, -179.75]] * 2))
    out = split_field(lon, det, 2, angle=True)
    deg = np.degrees(out[0])
    assert np.all(np.abs(deg) > 179.0)  # nothing lands near 0 deg
    steps = np.diff(np.unwrap(out[0]))
    assert np.allclose(steps, steps[0])  # evenly spaced across the line
    assert np.all((out >= -np.pi) & (out < np.pi))


def test_values_are_repeated_at_each_sub_pixel():
    a = np.array([[1, 2], [3, 4]], np.uint8)
    out = split_values(a, 2)
    assert out.dtype == np.uint8
    assert out.tolist() == [[1, 1, 2, 2], [1, 1, 2, 2], [3, 3, 4, 4], [3, 3, 4, 4]]


def test_the_m_grid_split_in_two_lands_on_the_i_grid(cases):
    """An M pixel covers 2 x 2 I pixels: the split M geolocation stands where the I grid's pixels are."""
    out, _, _ = cases.get(bands=tuple(BANDS))
    case = plan([out], bands=tuple(BANDS))
    g = case.cris[0]
    (geo_i,) = read_file(case.cover(g, "I5")[0].geo, kinds=("viirs_geo",))
    (geo_m,) = read_file(case.cover(g, "M15")[0].geo, kinds=("viirs_geo",))
    n = GRIDS["M"].cone_split
    split = split_geolocation(geo_m.lat_rad, geo_m.lon_rad, geo_m.height_m, GRIDS["M"].detectors, n)
    assert split[0].shape == geo_i.lat_rad.shape
    p_i = wgs84.geodetic_to_ecef(geo_i.lat_rad, geo_i.lon_rad, geo_i.height_m)
    p_m = wgs84.geodetic_to_ecef(*split)
    d = np.linalg.norm(p_i - p_m, axis=-1)
    ok = np.isfinite(d)
    assert ok.mean() > 0.8
    # within a tenth of an I pixel (375 m at nadir) nearly everywhere: the grids are built to nest
    assert np.median(d[ok]) < 10.0
    assert np.quantile(d[ok], 0.99) < 40.0
