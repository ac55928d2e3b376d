"""VIIRS granules prepared for the cone test: the same on any number of threads, and only the columns and
scans no cone can reach left out."""

import math

import numpy as np
import pytest

from monitor.assessment.inputs import SwathCache, offsets_rad, piece, reach_us
from monitor.collocation import collocate, reach, swath
from monitor.compiled.threads import parallel_threads
from monitor.config.assessment import AssessmentConfig
from monitor.core.constants import VIIRS_DETECTORS
from monitor.geometry import wgs84
from monitor.geometry.inverse import granule_geometry
from monitor.instrument.spectral import i5_band
from monitor.sdr import read_file
from monitor.sdr.pairing import neighbours
from monitor.sdr.readers import read_viirs_geo_scan


@pytest.fixture(scope="module")
def granule(case_plan):
    """The first VIIRS granule of the simulated case: GEO, SDR and the neighbours' adjacent scans."""
    v = case_plan.viirs[case_plan.cris[0].key][0]
    (geo,) = read_file(v.geo, kinds=("viirs_geo",))
    (sdr,) = read_file(v.sdr, kinds=("viirs_sdr",))
    before, after = neighbours(case_plan.viirs_all, v)
    halos = [None if n is None else read_viirs_geo_scan(n.geo, s) for n, s in ((before, -1), (after, 0))]
    return geo, sdr, halos


def _view_deg(geo, rows):
    """View angle from the geocentric nadir (deg) of the pixels of *rows*, from their scan's spacecraft."""
    sat = geo.sc_position_m[rows // VIIRS_DETECTORS]
    los = wgs84.geodetic_to_ecef(geo.lat_rad[rows], geo.lon_rad[rows], geo.height_m[rows]) - sat[:, None]
    cos = (
        -np.sum(los * sat[:, None], -1) / np.linalg.norm(los, axis=-1) / np.linalg.norm(sat, axis=-1)[:, None]
    )
    return np.degrees(np.arccos(cos))


def test_one_and_two_threads_prepare_the_same_granule(granule):
    geo, sdr, (before, after) = granule
    args = (geo.lat_rad, geo.lon_rad, geo.height_m, sdr.bt_k, sdr.good, i5_band("j01"), before, after)
    with parallel_threads(1):
        one = swath.swath_piece(*args)
    with parallel_threads(2):
        par = swath.swath_piece(*args)
    for name in ("ecef_m", "radiance", "area_vec_m2", "block_centre_m", "block_radius_m"):
        np.testing.assert_array_equal(getattr(one, name), getattr(par, name), err_msg=name)
    assert np.isfinite(par.radiance).mean() > 0.5


def test_view_columns_keep_every_pixel_seen_within_the_angle(granule):
    geo, _, _ = granule
    nscan = geo.lat_rad.shape[0] // VIIRS_DETECTORS
    rows = np.arange(nscan) * VIIRS_DETECTORS + VIIRS_DETECTORS // 2
    view = _view_deg(geo, rows)
    kept = reach.view_columns(geo.lat_rad, geo.lon_rad, geo.height_m, geo.sc_position_m, math.radians(40.0))
    inside = np.zeros(view.shape[1], bool)
    inside[kept] = True
    assert 0 < kept.start and kept.stop < view.shape[1]  # some columns left out on both sides
    assert np.all(inside[np.nonzero(view < 39.9)[1]])  # every pixel well within the angle is kept
    assert np.nanmin(view[:, ~inside]) > 39.9  # and what is left out is beyond it
    assert reach.view_columns(
        geo.lat_rad, geo.lon_rad, geo.height_m, geo.sc_position_m * np.nan, 0.7
    ) == slice(None)  # nothing to judge by: every column


def test_columns_no_cone_reaches_change_no_cone_sum(case_plan):
    """The prepared columns end beyond every cone of the granule's FOVs: the cone sums of every FOV are the
    same, bit for bit, as with every column prepared."""
    g = case_plan.cris[0]
    (geo,) = read_file(g.geo, kinds=("cris_geo",))
    fg, valid = granule_geometry(geo), geo.valid
    cfg, band = AssessmentConfig(), i5_band(case_plan.satellite)
    sel = (fg.sat_ecef_m[valid], fg.sbf_to_ecef[valid], fg.alpha_rad[valid], fg.beta_rad[valid])
    view = collocate.view_reach_rad(*sel, offsets_rad(cfg))
    assert math.radians(45) < view < math.radians(55)
    full, cut = (
        swath.ViirsSwath(
            [piece(v, case_plan.viirs_all, band, SwathCache(), reach) for v in case_plan.viirs[g.key]]
        )
        for reach in (math.inf, view)
    )
    assert all(c.shape[1] < f.shape[1] for f, c in zip(full.pieces, cut.pieces, strict=True))
    assert all(c.first_column > 0 and c.view_rad < math.pi for c in cut.pieces)
    a, b = (collocate.cone_sums(sw, *sel, offsets_rad(cfg)) for sw in (full, cut))
    np.testing.assert_array_equal(a.sums, b.sums)
    np.testing.assert_array_equal(a.weights, b.weights)
    assert np.isfinite(a.mean()).mean() > 0.9


def test_scans_no_cone_reaches_change_no_cone_sum(case_plan):
    """Prepared for one CrIS granule's observation times (+- the margin), a VIIRS granule keeps fewer
    scans, and every FOV's cone sums are the same, bit for bit, as with every scan prepared."""
    g = case_plan.cris[-1]
    (geo,) = read_file(g.geo, kinds=("cris_geo",))
    fg, valid = granule_geometry(geo), geo.valid
    cfg, band = AssessmentConfig(), i5_band(case_plan.satellite)
    sel = (fg.sat_ecef_m[valid], fg.sbf_to_ecef[valid], fg.alpha_rad[valid], fg.beta_rad[valid])
    seen = geo.for_time_us[geo.for_time_us > 0]
    span = reach_us(int(seen.min()), int(seen.max()))
    full, cut = (
        swath.ViirsSwath(
            [
                piece(v, case_plan.viirs_all, band, SwathCache(), 1.0, span_us=s)
                for v in case_plan.viirs[g.key]
            ]
        )
        for s in (None, span)
    )
    assert sum(c.shape[0] for c in cut.pieces) < sum(f.shape[0] for f in full.pieces)
    assert all(c.covers(*span) for c in cut.pieces)
    assert not any(c.covers(span[0] - 10**9, span[1] + 10**9) for c in cut.pieces if c.first_scan)
    for f, c in zip(full.pieces, cut.pieces, strict=True):  # the kept scans weigh as in the whole granule
        rows = slice(c.first_scan * VIIRS_DETECTORS, c.first_scan * VIIRS_DETECTORS + c.shape[0])
        cols = slice(c.first_column - f.first_column, c.first_column - f.first_column + c.shape[1])
        np.testing.assert_array_equal(c.area_vec_m2, f.area_vec_m2[rows, cols])
        np.testing.assert_array_equal(c.radiance, f.radiance[rows, cols])
    a, b = (collocate.cone_sums(sw, *sel, offsets_rad(cfg)) for sw in (full, cut))
    np.testing.assert_array_equal(a.sums, b.sums)
    np.testing.assert_array_equal(a.weights, b.weights)
    assert np.isfinite(a.mean()).mean() > 0.9
