"""The interval formulation of the cone test against a brute-force angle test on every pixel."""

import numpy as np
import pytest

from monitor import collocate
from monitor.assess import AssessConfig, _load_swath, _SwathCache
from monitor.geometry import wgs84
from monitor.geometry.inverse import granule_geometry
from monitor.geometry.perturb import perturbation_grid
from monitor.sdr import read_file
from monitor.sdr.pairing import plan
from monitor.spectral import i5_band


@pytest.fixture(scope="module")
def case_plan(cases):
    out, _, _ = cases.get()
    return plan([out])


@pytest.fixture(scope="module")
def scene(case_plan):
    g = case_plan.cris[0]
    (geo,) = read_file(g.geo, kinds=("cris_geo",))
    fg = granule_geometry(geo)
    swath = _load_swath(case_plan.viirs[g.key], case_plan.viirs_all, i5_band("j01"), _SwathCache())
    return fg, swath


def _brute(swath, sat, m, alpha, beta, offsets, half_angle):
    pos = swath.ecef_m.reshape(-1, 3).astype(float)
    rad = swath.radiance.reshape(-1)
    area = swath.area_vec_m2.reshape(-1, 3).astype(float)
    ok = np.isfinite(rad)
    vec = pos[ok] - sat
    dist = np.linalg.norm(vec, axis=1)
    d = vec / dist[:, None]
    los0 = m @ np.array([np.tan(alpha), np.tan(beta), 1.0])
    near = d @ (los0 / np.linalg.norm(los0)) > np.cos(0.03)
    d, dist, val, ar = d[near], dist[near], rad[ok][near], area[ok][near]
    w = np.abs(np.sum(ar * d, axis=1)) / dist**2  # the footprint projected across the view, / range^2
    mean = np.empty((len(offsets), len(offsets)))
    cover = np.empty_like(mean)
    for i, da in enumerate(offsets):
        for j, db in enumerate(offsets):
            los = m @ np.array([np.tan(alpha + da), np.tan(beta + db), 1.0])
            inside = d @ (los / np.linalg.norm(los)) >= np.cos(half_angle)
            mean[i, j] = np.sum(w[inside] * val[inside]) / np.sum(w[inside])
            cover[i, j] = np.sum(w[inside]) / (2 * np.pi * (1 - np.cos(half_angle)))
    return mean, cover


@pytest.mark.parametrize("scan,for_,fov", [(1, 14, 4), (2, 29, 8), (0, 0, 0)])
def test_interval_method_equals_brute_force(scene, scan, for_, fov):
    fg, swath = scene
    offsets = perturbation_grid(4, 900e-6)
    idx = (scan, for_, fov)
    mean, cover = collocate.cone_sums(
        swath,
        fg.sat_ecef_m[idx][None],
        fg.sbf_to_ecef[idx][None],
        fg.alpha_rad[idx][None],
        fg.beta_rad[idx][None],
        offsets,
    )
    bm, bc = _brute(
        swath,
        fg.sat_ecef_m[idx],
        fg.sbf_to_ecef[idx],
        fg.alpha_rad[idx],
        fg.beta_rad[idx],
        offsets,
        collocate.TOP_HAT[0][0],
    )
    np.testing.assert_allclose(mean[0], bm, rtol=1e-6)
    np.testing.assert_allclose(cover[0], bc, rtol=1e-6)
    # solid-angle weights fill the cone: coverage 1 inside the swath, also at nadir (FOR 15), where the
    # VIIRS scans overlap by a fraction of a detector (whole-pixel counting left ~1.2 % too much there)
    assert np.all(np.abs(bc - 1.0) < 0.01)


def test_fov_off_the_swath_has_no_coverage(scene):
    fg, swath = scene
    idx = (0, 14, 4)
    far = fg.sat_ecef_m[idx] + np.array([3e6, 0.0, 0.0])
    mean, cover = collocate.cone_sums(
        swath,
        far[None],
        fg.sbf_to_ecef[idx][None],
        fg.alpha_rad[idx][None],
        fg.beta_rad[idx][None],
        perturbation_grid(2, 450e-6),
    )
    assert np.all(np.nan_to_num(cover) < collocate.MIN_COVERAGE)


def test_spatial_response_kernel_is_a_weighted_stack_of_top_hats(scene):
    fg, swath = scene
    idx = (1, 10, 4)
    args = (
        swath,
        fg.sat_ecef_m[idx][None],
        fg.sbf_to_ecef[idx][None],
        fg.alpha_rad[idx][None],
        fg.beta_rad[idx][None],
        perturbation_grid(1, 450e-6),
    )
    resp, cov = collocate.cone_sums(*args, kernel=collocate.SPATIAL_RESPONSE)
    top, _ = collocate.cone_sums(*args)
    assert np.all(np.isfinite(resp)) and np.all(np.abs(cov - 1) < 0.03)
    assert np.max(np.abs(resp - top)) > 0  # a different weighting of the same pixels
    assert AssessConfig(kernel="response").kernel == "response"


def test_search_blocks_at_a_ragged_swath_edge(scene, case_plan):
    """Pixels are searched in 4 x 4 blocks; a swath whose width is no multiple of 4 still has every
    pixel of a cone that crosses its last, partial block column counted once."""
    fg, swath = scene
    idx = (1, 29, 4)
    los = fg.sbf_to_ecef[idx] @ np.array([np.tan(fg.alpha_rad[idx]), np.tan(fg.beta_rad[idx]), 1.0])
    los /= np.linalg.norm(los)
    centre = fg.sat_ecef_m[idx] + wgs84.intersect_ellipsoid(fg.sat_ecef_m[idx], los) * los
    row0, col0 = swath.nearest(centre[None])
    ncol = int(col0[0]) + 4 * 5 + 3  # the cone reaches past the cut
    assert ncol % collocate.BLOCK_PX
    v = case_plan.viirs[case_plan.cris[0].key][int(row0[0]) // swath.pieces[0].radiance.shape[0]]
    (vgeo,) = read_file(v.geo, kinds=("viirs_geo",))
    (vsdr,) = read_file(v.sdr, kinds=("viirs_sdr",))
    cut = collocate.build_swath(
        vgeo.lat_rad[:, :ncol],
        vgeo.lon_rad[:, :ncol],
        vgeo.height_m[:, :ncol],
        vsdr.bt_k[:, :ncol],
        vsdr.good[:, :ncol],
        i5_band("j01"),
    )
    assert cut.block_radius_m.shape[1] == -(-ncol // collocate.BLOCK_PX)
    offsets = perturbation_grid(2, 900e-6)
    mean, cover = collocate.cone_sums(
        cut,
        fg.sat_ecef_m[idx][None],
        fg.sbf_to_ecef[idx][None],
        fg.alpha_rad[idx][None],
        fg.beta_rad[idx][None],
        offsets,
    )
    bm, bc = _brute(
        cut,
        fg.sat_ecef_m[idx],
        fg.sbf_to_ecef[idx],
        fg.alpha_rad[idx],
        fg.beta_rad[idx],
        offsets,
        collocate.TOP_HAT[0][0],
    )
    assert 0.05 < bc.min() and bc.max() < 0.95  # the cut runs through the cones
    np.testing.assert_allclose(mean[0], bm, rtol=1e-6)
    np.testing.assert_allclose(cover[0], bc, rtol=1e-6)
